// libFuzzer target: opening a project file and reading all of it, as info,
// history, objects, export and check would: open (migrating an older
// version), list and load every scan with its layers, read the journal and
// the object tree, check the file.
#include "fuzz/fuzz_file.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/typed_layers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using scanbench::store::Project;
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "input.sbproj");
  for (const char* suffix : {"-wal", "-shm", "-journal"}) {
    std::error_code ignored;
    std::filesystem::remove(path.string() + suffix, ignored);
  }
  scanbench::fuzz::expect_refusal_or_success([&] {
    const Project project = Project::open(path);
    static_cast<void>(project.history());
    static_cast<void>(project.object_nodes());
    static_cast<void>(project.scan_color_corrections());
    for (const auto& stored : project.scans()) {
      static_cast<void>(project.load_scan(stored.id));
      static_cast<void>(scanbench::store::load_geometry(project, stored.id));
      static_cast<void>(scanbench::store::load_keep_mask(project, stored.id));
    }
    static_cast<void>(project.check());
  });
  return 0;
}
