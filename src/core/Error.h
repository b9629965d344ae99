#pragma once

#include <stdexcept>

namespace subscan {

/// An error the user can act on. what() is one complete sentence; the code that knows the file
/// name (ScanLoader, the CLI) prefixes it, so readers describe only the problem.
class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace subscan
