// The program names: the offline tools are cohaptic-lab's subcommands, and the server's
// old spellings of them fail with one line naming the new one (exit 2).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "support/run_program.h"

namespace cohaptic {
namespace {

const char* const kLabTools[] = {"probe",     "replay",    "study", "tradeoff",
                                 "stability", "summarize", "keygen"};

TEST(LabProgram, EveryToolIsASubcommandWithItsOwnHelp) {
  const testing::ProgramRun help = testing::run_program(COHAPTIC_LAB_EXE, "--help");
  EXPECT_EQ(help.exit_code, 0);
  for (const std::string tool : kLabTools) {
    EXPECT_NE(help.out.find("\n  " + tool + " "), std::string::npos) << tool << " missing from:\n"
                                                                     << help.out;
    const testing::ProgramRun own = testing::run_program(COHAPTIC_LAB_EXE, tool + " --help");
    EXPECT_EQ(own.exit_code, 0) << tool;
    EXPECT_NE(own.out.find("cohaptic-lab " + tool), std::string::npos) << own.out;
  }
  EXPECT_NE(testing::run_program(COHAPTIC_LAB_EXE, "").exit_code, 0);  // a subcommand is required
  EXPECT_NE(testing::run_program(COHAPTIC_LAB_EXE, "serve").exit_code, 0);
}

TEST(LabProgram, ALabToolNamedToTheServerFailsWithOneLineNamingTheLabCommand) {
  for (const std::string tool : kLabTools) {
    for (const std::string& arguments :
         {tool + " --help", "--log-level warn " + tool + " --scene /no/such.yaml"}) {
      const testing::ProgramRun run = testing::run_program(COHAPTIC_SERVER_EXE, arguments, true);
      EXPECT_EQ(run.exit_code, 2) << arguments << ": " << run.out;
      EXPECT_NE(run.out.find("run `cohaptic-lab " + tool + " ...`"), std::string::npos) << run.out;
      EXPECT_EQ(std::count(run.out.begin(), run.out.end(), '\n'), 1) << run.out;
    }
  }
  // Any other stray word is still an error of its own, not a pointer to cohaptic-lab.
  const testing::ProgramRun stray = testing::run_program(COHAPTIC_SERVER_EXE, "serve", true);
  EXPECT_NE(stray.exit_code, 0);
  EXPECT_NE(stray.out.find("serve"), std::string::npos) << stray.out;
  EXPECT_EQ(stray.out.find("cohaptic-lab"), std::string::npos) << stray.out;
}

}  // namespace
}  // namespace cohaptic
