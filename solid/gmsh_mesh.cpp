// Reads a Gmsh .geo (meshed here) or .msh file into a solid::Mesh through the Gmsh C++ API.
#include "gmsh_mesh.hpp"

#include <gmsh.h>

#include <algorithm>
#include <exception>
#include <fstream>
#include <map>
#include <set>
#include <unordered_map>

#include "error.hpp"
#include "runtime.hpp"

namespace solid {

namespace {

// Gmsh keeps global state: initialise for one read, always finalise.
struct GmshScope {
  explicit GmshScope(const GmshOptions& options) {
    std::vector<std::string> args{"gmsh"};
    for (const auto& [name, value] : options.parameters) {
      args.push_back("-setnumber");
      args.push_back(name);
      args.push_back(fmt::format("{:.17g}", value));
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    gmsh::initialize(static_cast<int>(argv.size()), argv.data(), false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
  }
  ~GmshScope() { gmsh::finalize(); }
};

// Gmsh's mesher throws some of its errors (a degenerate surface: "Unable to recover the edge")
// through code that cannot pass them on, which ends in std::terminate ("terminate called ...",
// SIGABRT, no file named). While Gmsh runs, a terminate handler names the key and the file and
// ends the job through the funnel instead. Gmsh runs on the main thread, where the funnel may
// call MPI.
struct TerminateScope {
  static inline std::string context;  // "solid.body[0].mesh: Gmsh could not mesh 'x.geo'"
  std::terminate_handler previous;
  explicit TerminateScope(std::string what) : previous(std::set_terminate(&TerminateScope::handler)) {
    context = std::move(what);
  }
  ~TerminateScope() { std::set_terminate(previous); }
  [[noreturn]] static void handler() {
    std::string why = "unknown error";
    try {
      if (const auto e = std::current_exception()) std::rethrow_exception(e);
    } catch (const std::string& s) {
      why = s;
    } catch (const char* s) {
      why = s;
    } catch (const std::exception& e) {
      why = e.what();
    } catch (...) {
    }
    fsi::abort_job("solid", fmt::format("{}: {}", context, why));
  }
};

std::string last_gmsh_error() {
  std::string e;
  try {
    gmsh::logger::getLastError(e);
  } catch (...) {
  }
  return e;
}

}  // namespace

Mesh read_gmsh(const std::filesystem::path& file, const GmshOptions& options,
               const std::string& key) {
  const std::string name = file.string();
  if (!std::filesystem::is_regular_file(file))
    throw fsi::InputError(fmt::format("{}: mesh file '{}' does not exist", key, name));
  const std::string ext = file.extension().string();
  if (ext != ".geo" && ext != ".msh")
    throw fsi::InputError(fmt::format(
        "{}: mesh file '{}' is not a Gmsh file (expected a .geo or .msh extension)", key, name));
  if (ext == ".msh") {
    std::ifstream in(file);
    std::string first;
    std::getline(in, first);
    if (first.rfind("$MeshFormat", 0) != 0)
      throw fsi::InputError(
          fmt::format("{}: mesh file '{}' is not a Gmsh mesh (no $MeshFormat header)", key, name));
  }

  GmshScope scope(options);
  const TerminateScope guard(fmt::format("{}: Gmsh could not {} '{}'", key,
                                         ext == ".geo" ? "mesh" : "read", name));
  try {
    gmsh::open(name);
    if (ext == ".geo") {
      gmsh::option::setNumber("Mesh.MeshSizeFactor", options.size_factor);
      gmsh::model::mesh::generate(2);
    }
    for (int k = 0; k < options.refine; ++k) gmsh::model::mesh::refine();
  } catch (...) {
    const std::string err = last_gmsh_error();
    throw fsi::InputError(fmt::format("{}: Gmsh could not read '{}': {}", key, name,
                                      err.empty() ? "not a valid Gmsh file" : err));
  }

  Mesh mesh;
  mesh.source = name;
  std::vector<std::size_t> tags;
  std::vector<double> coord, param;
  gmsh::model::mesh::getNodes(tags, coord, param, -1, -1, false, false);
  std::unordered_map<std::size_t, std::size_t> tag_index;
  for (std::size_t k = 0; k < tags.size(); ++k) tag_index[tags[k]] = k;

  // Triangles of every surface, grouped by surface for the orientation check.
  std::vector<std::array<std::size_t, 3>> tris;
  std::vector<int> group, tri_surface;
  gmsh::vectorpair surfaces;
  gmsh::model::getEntities(surfaces, 2);
  for (const auto& [dim, tag] : surfaces) {
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> etags, enodes;
    gmsh::model::mesh::getElements(types, etags, enodes, 2, tag);
    for (std::size_t k = 0; k < types.size(); ++k) {
      if (types[k] != 2)
        throw fsi::InputError(fmt::format(
            "{}: mesh '{}' has surface elements of Gmsh type {}; only 3-node triangles are "
            "supported (set Mesh.ElementOrder = 1 and no recombination)",
            key, name, types[k]));
      for (std::size_t e = 0; e < etags[k].size(); ++e) {
        tris.push_back({enodes[k][3 * e], enodes[k][3 * e + 1], enodes[k][3 * e + 2]});
        group.push_back(tag);
        tri_surface.push_back(tag);
      }
    }
  }
  if (tris.empty())
    throw fsi::InputError(
        fmt::format("{}: mesh '{}' holds no triangles (is it a 2D Gmsh mesh?)", key, name));

  // Keep the nodes that triangles use, numbered in order of appearance in Gmsh's node list.
  std::vector<int> new_index(tags.size(), -1);
  for (const auto& t : tris)
    for (auto n : t) new_index[tag_index.at(n)] = 0;
  int count = 0;
  for (std::size_t k = 0; k < tags.size(); ++k)
    if (new_index[k] == 0) {
      new_index[k] = count++;
      mesh.x.push_back(coord[3 * k]);
      mesh.x.push_back(coord[3 * k + 1]);
    }
  auto node_of = [&](std::size_t tag) { return new_index[tag_index.at(tag)]; };
  for (const auto& t : tris)
    mesh.triangles.push_back({node_of(t[0]), node_of(t[1]), node_of(t[2])});

  // Regions: physical surfaces; surfaces in none form the region "(unnamed)".
  std::map<int, int> surface_region;
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 2);
  for (const auto& [dim, ptag] : groups) {
    std::string pname;
    gmsh::model::getPhysicalName(dim, ptag, pname);
    if (pname.empty()) pname = std::to_string(ptag);
    std::vector<int> ents;
    gmsh::model::getEntitiesForPhysicalGroup(dim, ptag, ents);
    int r = mesh.region_index(pname);
    if (r < 0) {
      r = static_cast<int>(mesh.region_names.size());
      mesh.region_names.push_back(pname);
    }
    for (int e : ents) surface_region.emplace(e, r);
  }
  for (int s : tri_surface) {
    if (surface_region.count(s)) {
      mesh.triangle_region.push_back(surface_region[s]);
      continue;
    }
    int r = mesh.region_index("(unnamed)");
    if (r < 0) {
      r = static_cast<int>(mesh.region_names.size());
      mesh.region_names.push_back("(unnamed)");
    }
    surface_region[s] = r;
    mesh.triangle_region.push_back(r);
  }

  // Boundaries: physical curves (edge sets) and physical points (node sets).
  for (int dim : {1, 0}) {
    gmsh::vectorpair pg;
    gmsh::model::getPhysicalGroups(pg, dim);
    for (const auto& [d, ptag] : pg) {
      std::string pname;
      gmsh::model::getPhysicalName(d, ptag, pname);
      if (pname.empty()) pname = std::to_string(ptag);
      std::vector<int> ents;
      gmsh::model::getEntitiesForPhysicalGroup(d, ptag, ents);
      for (int ent : ents) {
        std::vector<int> types;
        std::vector<std::vector<std::size_t>> etags, enodes;
        gmsh::model::mesh::getElements(types, etags, enodes, d, ent);
        for (std::size_t k = 0; k < types.size(); ++k) {
          const int per = d == 1 ? (types[k] == 1 ? 2 : 0) : 1;
          if (per == 0) continue;
          for (std::size_t e = 0; e + per <= enodes[k].size(); e += per) {
            const auto ia = tag_index.find(enodes[k][e]);
            if (ia == tag_index.end() || new_index[ia->second] < 0) continue;
            if (d == 0) {
              mesh.node_sets[pname].push_back(new_index[ia->second]);
              continue;
            }
            const auto ib = tag_index.find(enodes[k][e + 1]);
            if (ib == tag_index.end() || new_index[ib->second] < 0) continue;
            mesh.boundaries[pname].push_back({new_index[ia->second], new_index[ib->second]});
          }
        }
      }
    }
  }
  finalize_mesh(mesh, group);
  return mesh;
}

}  // namespace solid
