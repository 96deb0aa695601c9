#pragma once
/// \file error.hpp
/// Errors thrown at strata's API boundary. strata never aborts on user input.
///
/// - `InputError`: malformed scene, mesh or argument; the message names the file, key or element.
///   The CLI maps it to exit code 2.
/// - `DivergenceError`: a simulation left the valid state space (NaN, energy blow-up, inverted
///   elements the material cannot handle); the message names the step and time. Exit code 3.
/// - `STRATA_VERIFY(cond, msg)`: an always-on check of an invariant that protects users; throws
///   `std::logic_error` with file:line.
#include <stdexcept>
#include <string>

namespace strata {

/// Bad input: the message is one line naming the offending file, key path or element.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run that diverged; the message names step and time.
class DivergenceError : public std::runtime_error {
 public:
  DivergenceError(const std::string& message, long step, double time)
      : std::runtime_error(message), m_step(step), m_time(time) {}
  long step() const { return m_step; }
  double time() const { return m_time; }

 private:
  long m_step;
  double m_time;
};

namespace detail {
[[noreturn]] void verify_failed(const char* condition, const std::string& message, const char* file,
                                int line);
}  // namespace detail

}  // namespace strata

/// Always-on invariant check; throws std::logic_error naming file:line (never aborts).
#define STRATA_VERIFY(condition, message)                                                         \
  do {                                                                                            \
    if (!(condition)) ::strata::detail::verify_failed(#condition, (message), __FILE__, __LINE__); \
  } while (false)
