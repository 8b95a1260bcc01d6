// The driver of a fuzz target built without libFuzzer (the GCC build of `make test`): runs
// LLVMFuzzerTestOneInput once on every file named on the command line, a directory's files
// in name order, so the corpora are replayed by every compiler and sanitizer build.
// Arguments starting with '-' are libFuzzer's options and are ignored, so
// `fuzz_NAME -runs=0 DIR` means "run the corpus once" with either driver. Fails if no input
// was found (a missing corpus must not pass); a broken property aborts, as under libFuzzer.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument.starts_with("-")) continue;
    if (std::filesystem::is_directory(argument)) {
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(argument))
        if (entry.is_regular_file()) files.push_back(entry.path());
      std::sort(files.begin(), files.end());
      inputs.insert(inputs.end(), files.begin(), files.end());
    } else if (std::filesystem::is_regular_file(argument)) {
      inputs.emplace_back(argument);
    } else {
      std::fprintf(stderr, "%s: no such file or directory\n", argument.c_str());
      return 2;
    }
  }
  if (inputs.empty()) {
    std::fprintf(stderr, "%s: no inputs (give corpus directories or files)\n", argv[0]);
    return 2;
  }
  for (const auto& input : inputs) {
    const std::vector<std::uint8_t> bytes = read_bytes(input);
    // libFuzzer passes a valid pointer even for an empty input; so do we.
    static const std::uint8_t empty = 0;
    LLVMFuzzerTestOneInput(bytes.empty() ? &empty : bytes.data(), bytes.size());
  }
  std::printf("%s: %zu inputs ran\n", argv[0], inputs.size());
  return 0;
}
