// CSV fields as RFC 4180 writes them: a field holding a comma, a double quote or a line
// break is enclosed in double quotes, with each double quote inside doubled. The study
// tables (trials.csv, summary.csv, plan.csv) are written and read back with these.
#pragma once

#include <string>
#include <vector>

namespace cohaptic {

/// `text` as one CSV field, quoted only when it must be.
std::string csv_field(const std::string& text);

/// The fields of one CSV line (without its line break), undoing csv_field().
std::vector<std::string> split_csv_line(const std::string& line);

}  // namespace cohaptic
