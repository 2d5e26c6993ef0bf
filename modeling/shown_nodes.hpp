// Which objects the model shows: the render model draws only these, and
// the exports write only their points unless asked for all.
#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "modeling/store/project.hpp"

namespace scanbench::modeling {

// For every node, whether it is shown: neither it nor any group above it is
// hidden.
std::map<std::int64_t, bool> shown_nodes(const std::vector<store::ObjectNode>& nodes);

}  // namespace scanbench::modeling
