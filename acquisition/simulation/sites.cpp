// The public entry point to the procedural sites; the layouts live in
// campus_site.cpp, street_site.cpp and path_site.cpp.
#include "acquisition/simulation/sites.hpp"

#include <cassert>

#include "acquisition/simulation/site_builder.hpp"

namespace scanbench::acquisition::sim {

std::vector<std::string> site_names() {
  return {"campus", "street", "path"};
}

int max_scan_count(std::string_view name) {
  return name == "path" ? detail::max_path_scans() : 64;
}

Site make_site(std::string_view name, std::uint64_t seed, int scan_count) {
  assert(scan_count >= 1 && "a campaign needs at least one scan");
  assert(scan_count <= max_scan_count(name) && "more scans than the site has room for");
  if (name == "street") return detail::make_street(seed, scan_count);
  if (name == "path") return detail::make_path(seed, scan_count);
  assert(name == "campus" && "unknown site name; see site_names()");
  return detail::make_campus(seed, scan_count);
}

}  // namespace scanbench::acquisition::sim
