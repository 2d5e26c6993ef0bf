// The object tree as of one revision of the project, kept by a connection
// between commands (Project::object_tree), so that a script of many tree
// commands does not read and verify every node's row again for each. It
// follows the connection's own commits; any other change (another
// process's commit, an undo or redo, a rolled-back batch) makes it be read
// again. Internal to modeling/.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "modeling/store/project.hpp"

namespace scanbench::store {

class ObjectTreeCache {
 public:
  using Tree = std::map<std::int64_t, ObjectNode>;

  // The live nodes at `revision`, or none when they are not known.
  const Tree* at(std::int64_t revision) const;

  // `tree` is what the project holds at `revision`.
  void remember(std::int64_t revision, Tree tree);

  // The open Edit wrote node `id` (`node`; none: deleted).
  void note_write(std::int64_t id, std::optional<ObjectNode> node);

  // The open Edit rolled back: its writes are dropped.
  void drop_writes();

  // The open Edit, begun when the project was at `revision`, committed as
  // revision + 1: the tree follows its writes when it was known at
  // `revision`, and is forgotten otherwise.
  void committed(std::int64_t revision);

  // Whatever happened, the tree is read again next time.
  void forget();

 private:
  std::optional<std::int64_t> revision_;
  Tree tree_;
  std::vector<std::pair<std::int64_t, std::optional<ObjectNode>>> writes_;
};

// What is open on a Project's connection (at most one Batch and, inside it
// or alone, at most one Edit; a ReadSnapshot), and its tree. Heap-held by
// the Project, so that its Edits keep a stable pointer when it moves.
struct Project::ConnectionState {
  bool batch = false;
  bool batch_failed = false;  // a refused Edit inside could not be rolled back
  bool edit = false;
  bool snapshot = false;
  ObjectTreeCache tree;
};

}  // namespace scanbench::store
