// XDMF (version 3 format, read by ParaView's XDMF readers) side files over .h5 data, and a
// consistency check of such a file against its data. Each step's XML is built once and kept;
// a rewrite concatenates the kept fragments.
#include "xdmf.hpp"

#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#include "h5.hpp"
#include "summary.hpp"

namespace fsi {

namespace {

std::string xml_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string xml_unescape(std::string text) {
  const std::pair<const char*, char> entities[] = {{"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&amp;", '&'}};
  for (const auto& [entity, c] : entities) {
    std::string e(entity);
    for (std::size_t pos = text.find(e); pos != std::string::npos; pos = text.find(e, pos + 1))
      text.replace(pos, e.size(), 1, c);
  }
  return text;
}

std::string dims_text(const std::vector<std::size_t>& dims) {
  std::string s;
  for (std::size_t k = 0; k < dims.size(); ++k) {
    if (k) s += ' ';
    s += std::to_string(dims[k]);
  }
  return s;
}

std::string absolute_dataset(std::string_view dataset) {
  std::string path;
  if (dataset.empty() || dataset.front() != '/') path.push_back('/');
  path.append(dataset);
  return path;
}

const char* step_indent = "      ";  // the steps' <Grid> lines, inside Xdmf/Domain/Grid

}  // namespace

std::vector<int> polyline_segments(std::span<const std::size_t> nodes_per_line) {
  std::vector<int> segments;
  int first = 0;
  for (std::size_t n : nodes_per_line) {
    for (std::size_t k = 0; k + 1 < n; ++k) {
      segments.push_back(first + int(k));
      segments.push_back(first + int(k) + 1);
    }
    first += int(n);
  }
  return segments;
}

std::vector<double> rectilinear_nodes(std::span<const double> x, std::span<const double> y) {
  std::vector<double> nodes;
  nodes.reserve(2 * x.size() * y.size());
  for (double yj : y)
    for (double xi : x) nodes.push_back(xi), nodes.push_back(yj);
  return nodes;
}

XdmfWriter::XdmfWriter(std::filesystem::path xdmf, const std::filesystem::path& h5, Grid grid,
                       std::string name)
    : m_xdmf(std::move(xdmf)), m_grid(std::move(grid)), m_name(std::move(name)) {
  auto folder = std::filesystem::absolute(m_xdmf).lexically_normal().parent_path();
  m_h5_ref = std::filesystem::absolute(h5).lexically_normal().lexically_relative(folder).generic_string();
  if (m_h5_ref.empty()) m_h5_ref = std::filesystem::absolute(h5).generic_string();
  if (const auto* r = std::get_if<XdmfStructured>(&m_grid); r && (r->nx < 2 || r->ny < 2))
    fail("XDMF {}: a structured grid needs at least 2 x 2 nodes, got {} x {}", m_xdmf.string(), r->nx, r->ny);
}

std::string XdmfWriter::data_item(std::string_view dataset, const std::vector<std::size_t>& dims,
                                  bool is_int) const {
  return fmt::format(
      "<DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">{}:{}</DataItem>",
      dims_text(dims), is_int ? "Int" : "Float", is_int ? 4 : 8, xml_escape(m_h5_ref),
      xml_escape(absolute_dataset(dataset)));
}

void XdmfWriter::add_step(double time, const std::vector<XdmfAttribute>& attributes,
                          std::string_view geometry) {
  const std::string in = step_indent;
  std::string xml = fmt::format("{}<Grid Name=\"{}_{:06d}\" GridType=\"Uniform\">\n", in,
                                xml_escape(m_name), m_steps.size());
  xml += fmt::format("{}  <Time Value=\"{}\"/>\n", in, time);

  std::vector<std::size_t> node_dims, cell_dims;
  if (const auto* r = std::get_if<XdmfStructured>(&m_grid)) {
    if (!geometry.empty())
      fail("XDMF {}: a structured grid takes no per-step geometry ('{}')", m_xdmf.string(), geometry);
    // Structured dimensions count nodes, slowest first.
    xml += fmt::format("{}  <Topology TopologyType=\"2DSMesh\" Dimensions=\"{} {}\"/>\n", in, r->ny, r->nx);
    xml += fmt::format("{}  <Geometry GeometryType=\"XY\">\n", in);
    xml += fmt::format("{}    {}\n", in, data_item(r->nodes, {r->ny * r->nx, 2}, false));
    xml += fmt::format("{}  </Geometry>\n", in);
    node_dims = {r->ny, r->nx};
    cell_dims = {r->ny - 1, r->nx - 1};
  } else {
    const bool is_mesh = std::holds_alternative<XdmfTriangles>(m_grid);
    const auto* mesh = std::get_if<XdmfTriangles>(&m_grid);
    const auto* lines = std::get_if<XdmfPolylines>(&m_grid);
    std::string topology = is_mesh ? mesh->topology : lines->segments;
    std::size_t n_cells = is_mesh ? mesh->n_triangles : lines->n_segments;
    std::size_t n_nodes = is_mesh ? mesh->n_nodes : lines->n_nodes;
    std::size_t per_cell = is_mesh ? 3 : 2;
    std::string fixed = is_mesh ? mesh->geometry : lines->geometry;
    std::string xy = geometry.empty() ? fixed : std::string(geometry);
    if (xy.empty())
      fail("XDMF {}: step at t = {} has no geometry and the grid has no fixed one", m_xdmf.string(), time);
    xml += fmt::format("{}  <Topology TopologyType=\"{}\" NumberOfElements=\"{}\" NodesPerElement=\"{}\">\n", in,
                       is_mesh ? "Triangle" : "Polyline", n_cells, per_cell);
    xml += fmt::format("{}    {}\n", in, data_item(topology, {n_cells, per_cell}, true));
    xml += fmt::format("{}  </Topology>\n", in);
    xml += fmt::format("{}  <Geometry GeometryType=\"XY\">\n", in);
    xml += fmt::format("{}    {}\n", in, data_item(xy, {n_nodes, 2}, false));
    xml += fmt::format("{}  </Geometry>\n", in);
    node_dims = {n_nodes};
    cell_dims = {n_cells};
  }

  for (const XdmfAttribute& a : attributes) {
    if (a.components != 1 && a.components != 3)
      fail("XDMF {}: attribute '{}' has {} components; a scalar has 1, a vector 3 (store a 2D vector "
           "as (vx, vy, 0))", m_xdmf.string(), a.name, a.components);
    std::vector<std::size_t> dims = a.center == XdmfCenter::node ? node_dims : cell_dims;
    if (a.components > 1) {
      // Vectors carry one value per component after the point index: flatten the grid shape.
      std::size_t n = std::accumulate(dims.begin(), dims.end(), std::size_t{1}, std::multiplies<>());
      dims = {n, a.components};
    }
    xml += fmt::format("{}  <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{}\">\n", in,
                       xml_escape(a.name), a.components == 1 ? "Scalar" : "Vector",
                       a.center == XdmfCenter::node ? "Node" : "Cell");
    xml += fmt::format("{}    {}\n", in, data_item(a.dataset, dims, false));
    xml += fmt::format("{}  </Attribute>\n", in);
  }
  xml += fmt::format("{}</Grid>\n", in);
  m_steps.push_back({time, std::move(xml)});
  rewrite();
}

void XdmfWriter::rewrite() const {
  std::string text = "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n";
  text += fmt::format("    <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
                      xml_escape(m_name));
  for (const Step& s : m_steps) text += s.xml;
  text += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  write_file_atomically(m_xdmf, text);
}

void XdmfWriter::resume(double t_last) {
  m_steps.clear();
  if (std::filesystem::exists(m_xdmf)) {
    std::ifstream in(m_xdmf);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    const std::string open = std::string("\n") + step_indent + "<Grid Name=";
    const std::string close = std::string("\n") + step_indent + "</Grid>\n";
    std::size_t pos = text.find(open);
    while (pos != std::string::npos) {
      std::size_t end = text.find(close, pos);
      if (end == std::string::npos) break;
      std::string xml = text.substr(pos + 1, end + close.size() - pos - 1);
      std::size_t t = xml.find("<Time Value=\"");
      if (t == std::string::npos)
        fail("XDMF {}: a step without <Time>; cannot resume from it", m_xdmf.string());
      double time = std::stod(xml.substr(t + 13));
      if (time <= t_last) m_steps.push_back({time, std::move(xml)});
      pos = text.find(open, end + 1);
    }
  }
  rewrite();
}

std::vector<std::string> xdmf_check(const std::filesystem::path& xdmf) {
  std::vector<std::string> problems;
  std::ifstream in(xdmf);
  if (!in) return {fmt::format("{}: cannot read", xdmf.string())};
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  if (text.find("<Xdmf") == std::string::npos || text.find("</Xdmf>") == std::string::npos)
    problems.push_back(fmt::format("{}: no <Xdmf> ... </Xdmf> element", xdmf.string()));

  std::map<std::string, H5File> files;
  std::size_t n_items = 0;
  // Each <DataItem attr="..." ...>file.h5:/dataset</DataItem> (the form this writer produces).
  for (std::size_t open = text.find("<DataItem"); open != std::string::npos;
       open = text.find("<DataItem", open + 1)) {
    std::size_t head_end = text.find('>', open), close = text.find("</DataItem>", open);
    if (head_end == std::string::npos || close == std::string::npos || close < head_end) {
      problems.push_back(fmt::format("{}: unterminated DataItem", xdmf.string()));
      break;
    }
    ++n_items;
    std::map<std::string, std::string> attrs;
    const std::string head = text.substr(open + 9, head_end - open - 9);
    for (std::size_t eq = head.find("=\""); eq != std::string::npos; eq = head.find("=\"", eq + 1)) {
      std::size_t key_start = head.rfind(' ', eq) + 1, value_end = head.find('"', eq + 2);
      if (value_end == std::string::npos) break;
      attrs[head.substr(key_start, eq - key_start)] = head.substr(eq + 2, value_end - eq - 2);
      eq = value_end;
    }
    std::string ref = xml_unescape(text.substr(head_end + 1, close - head_end - 1));
    ref.erase(0, ref.find_first_not_of(" \t\r\n"));
    ref.erase(ref.find_last_not_of(" \t\r\n") + 1);
    auto say = [&](const std::string& what) { problems.push_back(fmt::format("{}: '{}': {}", xdmf.string(), ref, what)); };
    if (attrs["Format"] != "HDF") {
      say("Format is not HDF");
      continue;
    }
    std::size_t colon = ref.find(":/");
    if (colon == std::string::npos) {
      say("not of the form file.h5:/dataset");
      continue;
    }
    std::filesystem::path h5 = xdmf.parent_path() / ref.substr(0, colon);
    std::string dataset = ref.substr(colon + 1);
    try {
      auto found = files.find(h5.string());
      if (found == files.end()) found = files.emplace(h5.string(), H5File(h5, H5File::Mode::read_only)).first;
      const H5File& file = found->second;
      if (!file.exists(dataset)) {
        say("no such dataset");
        continue;
      }
      std::vector<std::size_t> dims;
      std::istringstream d(attrs["Dimensions"]);
      for (std::size_t n; d >> n;) dims.push_back(n);
      if (file.shape(dataset) != dims)
        say(fmt::format("dataset shape {} but Dimensions=\"{}\"", dims_text(file.shape(dataset)), attrs["Dimensions"]));
      std::string expected = (attrs["NumberType"] == "Int" ? "int" : "float") +
                             std::to_string(8 * std::stoi(attrs.count("Precision") ? attrs["Precision"] : "4"));
      if (file.type_name(dataset) != expected)
        say(fmt::format("stored as {} but declared {}", file.type_name(dataset), expected));
    } catch (const std::exception& e) {
      say(e.what());
    }
  }
  if (n_items == 0) problems.push_back(fmt::format("{}: no DataItem", xdmf.string()));
  return problems;
}

}  // namespace fsi
