// A run's stats.csv as columns by name, for the tests that read what the frame loop wrote.
#pragma once

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/files.h"

namespace surge {

inline std::map<std::string, std::vector<double>> readStats(const fs::path& dir) {
  std::ifstream in(dir / "stats.csv");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (size_t k = 0; k < names.size() && std::getline(row, cell, ','); ++k)
      columns[names[k]].push_back(std::strtod(cell.c_str(), nullptr));
  }
  return columns;
}

}  // namespace surge
