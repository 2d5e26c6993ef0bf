// The public entry point to the procedural sites; the layouts live in
// campus_site.cpp and street_site.cpp.
#include "acquisition/simulation/sites.hpp"

#include <cassert>

#include "acquisition/simulation/site_builder.hpp"

namespace scanbench::acquisition::sim {

std::vector<std::string> site_names() {
  return {"campus", "street"};
}

Site make_site(std::string_view name, std::uint64_t seed, int scan_count) {
  assert(scan_count >= 1 && "a campaign needs at least one scan");
  if (name == "street") return detail::make_street(seed, scan_count);
  assert(name == "campus" && "unknown site name; see site_names()");
  return detail::make_campus(seed, scan_count);
}

}  // namespace scanbench::acquisition::sim
