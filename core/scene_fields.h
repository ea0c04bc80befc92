// The declaration of every scene key, once: a visitor walks the Scene and names each field with its
// description and allowed range. Readers (JSON), writers (scene.json) and the key documentation are visitors.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/scene.h"

namespace surge {

struct FieldInfo {
  const char* description = "";
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool minExclusive = false;
  bool required = false;
  const char* units = "";
};

class SceneVisitor {
 public:
  virtual ~SceneVisitor() = default;
  virtual void text(const char* key, std::string& value, const FieldInfo& info) = 0;
  virtual void choice(const char* key, std::string& value, const std::vector<std::string>& options,
                      const FieldInfo& info) = 0;
  // A list of distinct names, each one of `options` (domain.open's faces).
  virtual void choices(const char* key, std::vector<std::string>& values, const std::vector<std::string>& options,
                       const FieldInfo& info) = 0;
  virtual void integer(const char* key, int& value, const FieldInfo& info) = 0;
  virtual void real(const char* key, double& value, const FieldInfo& info) = 0;
  // A vector of `dimensions` components (the scene's, or 3 when `always3`).
  virtual void vector(const char* key, Eigen::Vector3d& value, const FieldInfo& info, bool always3 = false) = 0;
  // An array of 1 to 3 numbers whose length depends on the context (a box's size, a heightfield's extents).
  virtual void reals(const char* key, std::vector<double>& values, const FieldInfo& info) = 0;
  // One formula of x, y, z per component (core/expression.h), `dimensions` of them; a number is a formula too.
  virtual void formulas(const char* key, std::vector<std::string>& values, const FieldInfo& info) = 0;
  virtual void group(const char* key, const FieldInfo& info, const std::function<void()>& body) = 0;
  // A list of objects: size(), resize(n), and visitItem(i) which visits item i's fields.
  virtual void list(const char* key, const FieldInfo& info, const std::function<size_t()>& size,
                    const std::function<void(size_t)>& resize, const std::function<void(size_t)>& visitItem) = 0;
};

// A key's FieldInfo: described (with its units), required, positive, or at least `min` (and at most `max`).
namespace field {
FieldInfo info(const char* description, const char* units = "");
FieldInfo required(const char* description, const char* units = "");
FieldInfo positive(const char* description, const char* units = "", bool isRequired = false);
FieldInfo atLeast(double min, const char* description, const char* units = "", double max = 1e300);
}  // namespace field

// Visits every key of the scene, in file order; a fluid method's own keys under `solver` come from its
// registration (SolverMethodEntry::declareKeys, core/scene.h), after the keys the methods share.
void visitScene(Scene& scene, SceneVisitor& visitor);

// A number as the scene's messages and its key table print it (up to 10 significant digits).
std::string formatNumber(double value);

// Checks a scene just read from `where` and resolves its derived defaults (core/scene_validate.cpp); InputError
// naming `where` and the key.
void validateScene(Scene& scene, const std::string& where);

}  // namespace surge
