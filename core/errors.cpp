#include "core/errors.h"

namespace surge {

InputError::InputError(const std::string& where, const std::string& key, const std::string& message)
    : Error(kExitBadInput, where + ": " + key + ": " + message) {}

InputError::InputError(const std::string& where, const std::string& message)
    : Error(kExitBadInput, where + ": " + message) {}

}  // namespace surge
