#include "modeling/store/object_tree_cache.hpp"

namespace scanbench::store {

const ObjectTreeCache::Tree* ObjectTreeCache::at(std::int64_t revision) const {
  return revision_ == revision ? &tree_ : nullptr;
}

void ObjectTreeCache::remember(std::int64_t revision, Tree tree) {
  tree_ = std::move(tree);
  revision_ = revision;
}

void ObjectTreeCache::note_write(std::int64_t id, std::optional<ObjectNode> node) {
  writes_.emplace_back(id, std::move(node));
}

void ObjectTreeCache::drop_writes() {
  writes_.clear();
}

void ObjectTreeCache::committed(std::int64_t revision) {
  if (revision_ != revision) {
    forget();
    return;
  }
  for (auto& [id, node] : writes_) {
    if (node) {
      tree_.insert_or_assign(id, std::move(*node));
    } else {
      tree_.erase(id);
    }
  }
  writes_.clear();
  revision_ = revision + 1;
}

void ObjectTreeCache::forget() {
  revision_.reset();
  tree_.clear();
  writes_.clear();
}

}  // namespace scanbench::store
