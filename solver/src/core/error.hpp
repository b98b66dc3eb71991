// The one exception type of the solver: a message meant for the user, naming the file and what is wrong.
#pragma once
#include <stdexcept>
#include <string>

namespace pd {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace pd
