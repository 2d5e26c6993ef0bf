#include "modeling/shown_nodes.hpp"

namespace scanbench::modeling {

std::map<std::int64_t, bool> shown_nodes(const std::vector<store::ObjectNode>& nodes) {
  std::map<std::int64_t, const store::ObjectNode*> by_id;
  for (const store::ObjectNode& n : nodes) by_id[n.id] = &n;
  std::map<std::int64_t, bool> shown;
  for (const store::ObjectNode& n : nodes) {
    bool visible = true;
    for (const store::ObjectNode* at = &n; at;) {
      visible = visible && !at->hidden;
      const auto parent = at->parent ? by_id.find(*at->parent) : by_id.end();
      at = parent == by_id.end() ? nullptr : parent->second;
    }
    shown[n.id] = visible;
  }
  return shown;
}

}  // namespace scanbench::modeling
