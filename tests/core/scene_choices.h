// For tests: the choices a scene key takes, as `surge keys` documents them ("one of `a`, `b`"), so that a test
// can hold a registry (solver methods, shapes, surface methods) against the scene's declaration.
#pragma once

#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "core/scene.h"

namespace surge {

// `key` as the key table names it: "solver.method", "colliders[i].shape".
inline std::vector<std::string> sceneChoices(const std::string& key) {
  const std::string table = sceneKeysMarkdown();
  const size_t row = table.find("| `" + key + "` |");
  EXPECT_NE(row, std::string::npos) << key;
  if (row == std::string::npos) return {};
  const std::string line = table.substr(row, table.find('\n', row) - row);
  const size_t oneOf = line.find("one of ");
  EXPECT_NE(oneOf, std::string::npos) << key;
  if (oneOf == std::string::npos) return {};
  const std::string choices = line.substr(oneOf, line.find('|', oneOf) - oneOf);
  std::vector<std::string> names;
  const std::regex quoted("`([a-z0-9_]+)`");
  for (auto it = std::sregex_iterator(choices.begin(), choices.end(), quoted); it != std::sregex_iterator(); ++it)
    names.push_back((*it)[1]);
  return names;
}

}  // namespace surge
