// A run's CSV files (stats.csv as columns by name), for the tests that read what the frame loop wrote.
#pragma once

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/files.h"

namespace surge {

// A CSV file's rows as cells, the header first.
inline std::vector<std::vector<std::string>> readCsvRows(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::stringstream cells(line);
    rows.emplace_back();
    for (std::string cell; std::getline(cells, cell, ',');) rows.back().push_back(cell);
  }
  return rows;
}

inline std::map<std::string, std::vector<double>> readStats(const fs::path& dir) {
  const auto rows = readCsvRows(dir / "stats.csv");
  std::map<std::string, std::vector<double>> columns;
  for (size_t r = 1; r < rows.size(); ++r)
    for (size_t k = 0; k < rows[0].size() && k < rows[r].size(); ++k)
      columns[rows[0][k]].push_back(std::strtod(rows[r][k].c_str(), nullptr));
  return columns;
}

}  // namespace surge
