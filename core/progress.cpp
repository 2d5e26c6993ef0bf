#include "core/progress.hpp"

#include "core/errors.hpp"

namespace scanbench::core {

void Progress::throw_if_cancelled(std::string_view stage) const {
  if (cancel_requested()) throw Cancelled(std::string(stage));
}

}  // namespace scanbench::core
