// One headless device for a whole test executable (creating contexts is
// slow on llvmpipe), current on the calling thread.
#pragma once

#include <memory>

#include "render/device.hpp"

namespace scanbench::render::test {

inline RenderDevice& shared_device() {
  static const std::unique_ptr<RenderDevice> shared = make_headless_device();
  shared->make_current();
  return *shared;
}

}  // namespace scanbench::render::test
