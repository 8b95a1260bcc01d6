#include "support/csv_table.h"

#include <gtest/gtest.h>

#include <fstream>

#include "common/util/csv.h"

namespace cohaptic::testing {

std::vector<CsvRow> read_csv_table(const std::filesystem::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in) << "cannot read " << file;
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split_csv_line(line);
  std::vector<CsvRow> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = split_csv_line(line);
    EXPECT_EQ(fields.size(), header.size()) << file << ": " << line;
    CsvRow& row = rows.emplace_back();
    for (std::size_t i = 0; i < header.size() && i < fields.size(); ++i) row[header[i]] = fields[i];
  }
  return rows;
}

}  // namespace cohaptic::testing
