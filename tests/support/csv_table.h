// A CSV file the programs wrote, read back as rows of column name -> text (the first line
// names the columns). A row whose field count differs from the header's fails the test.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace cohaptic::testing {

using CsvRow = std::map<std::string, std::string>;

std::vector<CsvRow> read_csv_table(const std::filesystem::path& file);

}  // namespace cohaptic::testing
