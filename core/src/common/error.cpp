#include "strata/core/common/error.hpp"

#include <sstream>

namespace strata::detail {

void verify_failed(const char* condition, const std::string& message, const char* file, int line) {
  std::ostringstream out;
  out << file << ":" << line << ": check failed (" << condition << "): " << message;
  throw std::logic_error(out.str());
}

}  // namespace strata::detail
