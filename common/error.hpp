// Errors: one funnel. User input problems are fsi::InputError (message names key, value, file);
// everything else fatal is fsi::Error. Every program's main catches both, prints
// "[role] ERROR: ..." and calls MPI_Abort(MPI_COMM_WORLD, 1) so that no process is left waiting.
#pragma once

#include <fmt/format.h>

#include <stdexcept>
#include <string>

namespace fsi {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad user input: a scene key, a mesh file, a command-line argument.
class InputError : public Error {
 public:
  using Error::Error;
};

template <class... Args>
[[noreturn]] void fail(fmt::format_string<Args...> f, Args&&... args) {
  throw Error(fmt::format(f, std::forward<Args>(args)...));
}

[[noreturn]] inline void assertion_failed(const char* cond, const char* file, int line) {
  throw Error(fmt::format("internal error: '{}' does not hold ({}:{}); please report it", cond, file, line));
}

// Internal invariant, checked in debug builds only (release builds define NDEBUG). A violation
// goes through the funnel like any error, so the whole job ends with the place named.
#ifdef NDEBUG
#define FSI_ASSERT(cond) ((void)0)
#else
#define FSI_ASSERT(cond) ((cond) ? (void)0 : ::fsi::assertion_failed(#cond, __FILE__, __LINE__))
#endif

}  // namespace fsi
