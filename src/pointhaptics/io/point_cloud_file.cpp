#include <pointhaptics/io/point_cloud_file.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/input_file.hpp>
#include <pointhaptics/geometry/neighbour_search.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

namespace pointhaptics {
namespace {

constexpr double implausible = 1e6;  // m: a coordinate beyond this is a unit or endianness mistake

// What a reader gathers before the checks.
struct RawCloud {
  std::vector<Vec3> X;
  std::vector<double> volume;       // empty: none given
  std::vector<unsigned char> held;  // empty: none given
};

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// ---- text: .xyz, .txt, .csv ----

// The columns of x, y, z, fixed, volume (-1: absent) from a header line, or empty if it is not one.
std::optional<std::array<int, 5>> header_columns(const std::vector<std::string>& fields) {
  std::array<int, 5> col{-1, -1, -1, -1, -1};
  const char* names[5] = {"x", "y", "z", "fixed", "volume"};
  for (std::size_t f = 0; f < fields.size(); ++f)
    for (int k = 0; k < 5; ++k)
      if (lower(fields[f]) == names[k]) col[k] = static_cast<int>(f);
  if (col[0] < 0 || col[1] < 0 || col[2] < 0) return std::nullopt;
  return col;
}

RawCloud parse_text(std::string_view data, bool csv, const std::string& name) {
  RawCloud raw;
  std::array<int, 5> col{0, 1, 2, 3, 4};
  bool have_header = false, first = true;
  int n_fields = -1;
  std::size_t pos = 0;
  int line_no = 0;
  std::vector<std::string> fields;
  while (pos < data.size()) {
    std::size_t eol = data.find('\n', pos);
    if (eol == std::string_view::npos) eol = data.size();
    std::string_view line = data.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    // split on the separator (csv: commas, spaces around them allowed; else whitespace)
    fields.clear();
    std::size_t i = 0;
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i == line.size() || line[i] == '#') continue;
    std::string current;
    for (; i <= line.size(); ++i) {
      const bool end = i == line.size();
      const char c = end ? ',' : line[i];
      const bool separator = csv ? c == ',' : std::isspace(static_cast<unsigned char>(c)) != 0 || end;
      if (separator) {
        while (!current.empty() && std::isspace(static_cast<unsigned char>(current.back()))) current.pop_back();
        if (csv || !current.empty()) fields.push_back(current);
        current.clear();
      } else if (!(csv && current.empty() && std::isspace(static_cast<unsigned char>(c)))) {
        current += c;
      }
    }
    if (first) {
      first = false;
      if (auto h = header_columns(fields)) {
        col = *h;
        have_header = true;
        n_fields = static_cast<int>(fields.size());
        continue;
      }
    }
    if (n_fields < 0) {
      n_fields = static_cast<int>(fields.size());
      if (n_fields < 3 || n_fields > 5)
        throw Error(fmt::format("{}:{}: expected x y z [fixed [volume]] (3 to 5 numbers), got {} fields", name, line_no,
                                n_fields));
      if (!have_header) {
        col = {0, 1, 2, n_fields > 3 ? 3 : -1, n_fields > 4 ? 4 : -1};
      }
    }
    if (static_cast<int>(fields.size()) != n_fields)
      throw Error(fmt::format("{}:{}: expected {} fields like the lines before, got {}", name, line_no, n_fields,
                              fields.size()));
    auto number = [&](int c, const char* what) {
      const std::string& f = fields[static_cast<std::size_t>(c)];
      double v = 0;
      auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
      if (ec != std::errc() || end != f.data() + f.size())
        throw Error(fmt::format("{}:{}: {} \"{}\" is not a number", name, line_no, what, f));
      return v;
    };
    const Vec3 x(number(col[0], "x"), number(col[1], "y"), number(col[2], "z"));
    raw.X.push_back(x);
    if (col[3] >= 0) {
      const double held = number(col[3], "fixed");
      if (held != 0 && held != 1)
        throw Error(
            fmt::format("{}:{}: fixed = {} must be 0 or 1", name, line_no, fields[static_cast<std::size_t>(col[3])]));
      raw.held.push_back(held == 1 ? 1 : 0);
    }
    if (col[4] >= 0) raw.volume.push_back(number(col[4], "volume"));
    if (raw.X.size() > static_cast<std::size_t>(std::numeric_limits<index_t>::max() / 2))
      throw Error(fmt::format("{}: too many points", name));
  }
  return raw;
}

// ---- PLY ----

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

std::optional<PlyType> ply_type(std::string_view t) {
  static const std::pair<std::string_view, PlyType> names[] = {
      {"char", PlyType::I8},   {"int8", PlyType::I8},     {"uchar", PlyType::U8},   {"uint8", PlyType::U8},
      {"short", PlyType::I16}, {"int16", PlyType::I16},   {"ushort", PlyType::U16}, {"uint16", PlyType::U16},
      {"int", PlyType::I32},   {"int32", PlyType::I32},   {"uint", PlyType::U32},   {"uint32", PlyType::U32},
      {"float", PlyType::F32}, {"float32", PlyType::F32}, {"double", PlyType::F64}, {"float64", PlyType::F64}};
  for (const auto& [n, type] : names)
    if (n == t) return type;
  return std::nullopt;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::I8:
    case PlyType::U8: return 1;
    case PlyType::I16:
    case PlyType::U16: return 2;
    case PlyType::I32:
    case PlyType::U32:
    case PlyType::F32: return 4;
    case PlyType::F64: return 8;
  }
  return 0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::F32;
  bool list = false;
  PlyType count_type = PlyType::U8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

template <class T>
T load(const unsigned char* p, bool swap) {
  std::array<unsigned char, sizeof(T)> b;
  std::memcpy(b.data(), p, sizeof(T));
  if (swap) std::reverse(b.begin(), b.end());
  T v;
  std::memcpy(&v, b.data(), sizeof(T));
  return v;
}

double load_binary(PlyType t, const unsigned char* p, bool swap) {
  switch (t) {
    case PlyType::I8: return static_cast<std::int8_t>(p[0]);
    case PlyType::U8: return p[0];
    case PlyType::I16: return load<std::int16_t>(p, swap);
    case PlyType::U16: return load<std::uint16_t>(p, swap);
    case PlyType::I32: return load<std::int32_t>(p, swap);
    case PlyType::U32: return load<std::uint32_t>(p, swap);
    case PlyType::F32: return load<float>(p, swap);
    case PlyType::F64: return load<double>(p, swap);
  }
  return 0;
}

RawCloud parse_ply(std::string_view data, const std::string& name) {
  // header: text lines up to end_header
  std::size_t pos = 0;
  int line_no = 0;
  auto next_line = [&]() -> std::optional<std::string> {
    if (pos >= data.size()) return std::nullopt;
    std::size_t eol = data.find('\n', pos);
    if (eol == std::string_view::npos) eol = data.size();
    std::string line(data.substr(pos, eol - pos));
    pos = std::min(data.size(), eol + 1);
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  auto magic = next_line();
  if (!magic || *magic != "ply")
    throw Error(fmt::format("{}: not a PLY file (it must start with the line \"ply\")", name));
  enum class Format { ASCII, LITTLE, BIG } format = Format::ASCII;
  bool have_format = false;
  std::vector<PlyElement> elements;
  for (;;) {
    auto line = next_line();
    if (!line) throw Error(fmt::format("{}: the PLY header has no end_header line", name));
    std::istringstream words(*line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") break;
    if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      std::string f, version;
      words >> f >> version;
      if (f == "ascii") format = Format::ASCII;
      else if (f == "binary_little_endian") format = Format::LITTLE;
      else if (f == "binary_big_endian") format = Format::BIG;
      else throw Error(fmt::format("{}:{}: unknown PLY format \"{}\"", name, line_no, f));
      have_format = true;
    } else if (keyword == "element") {
      PlyElement e;
      std::string count;
      words >> e.name >> count;
      auto [end, ec] = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (e.name.empty() || ec != std::errc() || end != count.data() + count.size())
        throw Error(fmt::format("{}:{}: malformed element line \"{}\"", name, line_no, *line));
      elements.push_back(e);
    } else if (keyword == "property") {
      if (elements.empty()) throw Error(fmt::format("{}:{}: a property before any element", name, line_no));
      PlyProperty p;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> p.name;
        auto ct = ply_type(count_type), it = ply_type(item_type);
        if (!ct || !it || p.name.empty())
          throw Error(fmt::format("{}:{}: malformed list property \"{}\"", name, line_no, *line));
        p.list = true;
        p.count_type = *ct;
        p.type = *it;
      } else {
        words >> p.name;
        auto t = ply_type(type);
        if (!t || p.name.empty())
          throw Error(fmt::format("{}:{}: unknown property type in \"{}\"", name, line_no, *line));
        p.type = *t;
      }
      elements.back().properties.push_back(p);
    } else {
      throw Error(fmt::format("{}:{}: unknown PLY header keyword \"{}\"", name, line_no, keyword));
    }
  }
  if (!have_format) throw Error(fmt::format("{}: the PLY header has no format line", name));
  // the vertex element, and the elements before it (skipped)
  std::size_t vertex_index = elements.size();
  for (std::size_t e = 0; e < elements.size(); ++e)
    if (elements[e].name == "vertex") {
      if (vertex_index != elements.size())
        throw Error(fmt::format("{}: the PLY header declares two vertex elements", name));
      vertex_index = e;
    }
  if (vertex_index == elements.size()) throw Error(fmt::format("{}: the PLY file has no vertex element", name));
  for (const PlyElement& e : elements)
    if (e.name == "face" && e.count > 0)
      throw Error(fmt::format("{}: a surface mesh ({} faces), not a point cloud (a scene volume-samples it as a mesh)",
                              name, e.count));
  const PlyElement& vertex = elements[vertex_index];
  int ix = -1, iy = -1, iz = -1, ifixed = -1, ivolume = -1;
  for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
    const std::string& n = vertex.properties[p].name;
    const int k = static_cast<int>(p);
    if (vertex.properties[p].list) continue;
    if (n == "x") ix = k;
    else if (n == "y") iy = k;
    else if (n == "z") iz = k;
    else if (n == "fixed" || n == "held") ifixed = k;
    else if (n == "volume") ivolume = k;
  }
  if (ix < 0 || iy < 0 || iz < 0) throw Error(fmt::format("{}: the vertex element lacks x, y or z", name));
  const std::size_t remaining = data.size() - pos;
  RawCloud raw;
  std::vector<double> values(vertex.properties.size());
  auto store = [&](std::uint64_t v) {
    const Vec3 x(values[static_cast<std::size_t>(ix)], values[static_cast<std::size_t>(iy)],
                 values[static_cast<std::size_t>(iz)]);
    raw.X[v] = x;
    if (ifixed >= 0) {
      const double held = values[static_cast<std::size_t>(ifixed)];
      if (held != 0 && held != 1) throw Error(fmt::format("{}: vertex {}: fixed = {} must be 0 or 1", name, v, held));
      raw.held[v] = held == 1 ? 1 : 0;
    }
    if (ivolume >= 0) raw.volume[v] = values[static_cast<std::size_t>(ivolume)];
  };
  auto reserve = [&](std::uint64_t count) {
    raw.X.resize(count);
    if (ifixed >= 0) raw.held.resize(count);
    if (ivolume >= 0) raw.volume.resize(count);
  };
  if (format == Format::ASCII) {
    // elements before the vertices: one line per item
    for (std::size_t e = 0; e < vertex_index; ++e)
      for (std::uint64_t k = 0; k < elements[e].count; ++k)
        if (!next_line()) throw Error(fmt::format("{}: truncated in element \"{}\"", name, elements[e].name));
    // a vertex line holds at least 2 characters per property: a count beyond that is a lie
    if (vertex.count > remaining / (2 * vertex.properties.size()) + 1)
      throw Error(
          fmt::format("{}: declares {} vertices but holds only {} bytes of data", name, vertex.count, remaining));
    reserve(vertex.count);
    for (std::uint64_t v = 0; v < vertex.count; ++v) {
      auto line = next_line();
      if (!line) throw Error(fmt::format("{}: truncated: {} of {} vertices", name, v, vertex.count));
      const char* p = line->data();
      const char* end = p + line->size();
      for (std::size_t k = 0; k < vertex.properties.size(); ++k) {
        while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
        if (vertex.properties[k].list)
          throw Error(fmt::format("{}: list properties in vertices are not supported", name));
        auto [next, ec] = std::from_chars(p, end, values[k]);
        if (ec != std::errc())
          throw Error(fmt::format("{}:{}: vertex {}: expected {} numbers", name, line_no, v, vertex.properties.size()));
        p = next;
      }
      store(v);
    }
    // what follows the vertices must be the later elements' lines, no more: a file holding more vertex
    // lines than its header declares was silently cut to the declared count
    std::uint64_t later = 0;
    for (std::size_t e = vertex_index + 1; e < elements.size(); ++e) later += elements[e].count;
    std::uint64_t extra = 0;
    while (auto line = next_line())
      if (line->find_first_not_of(" \t") != std::string::npos) ++extra;
    if (extra > later)
      throw Error(fmt::format("{}: holds {} more data lines than its header declares ({} vertices)", name,
                              extra - later, vertex.count));
    return raw;
  }
  // binary: fixed-size items (list properties only outside the vertices, skipped item by item)
  const bool swap = (format == Format::BIG) != (std::endian::native == std::endian::big);
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  std::size_t at = pos;
  for (std::size_t e = 0; e < vertex_index; ++e) {
    // fixed-size items are skipped at once (a huge count must not loop); items with lists one by one,
    // each of which takes at least a byte, so the loop ends with the data
    bool has_list = false;
    std::uint64_t item = 0;
    for (const PlyProperty& p : elements[e].properties) {
      has_list = has_list || p.list;
      item += ply_size(p.type);
    }
    if (!has_list) {
      if (item > 0 && elements[e].count > (data.size() - at) / item)
        throw Error(fmt::format("{}: truncated in element \"{}\" ({} items declared)", name, elements[e].name,
                                elements[e].count));
      at += static_cast<std::size_t>(elements[e].count * item);
      continue;
    }
    for (std::uint64_t k = 0; k < elements[e].count; ++k)
      for (const PlyProperty& p : elements[e].properties) {
        std::uint64_t n = 1;
        if (p.list) {
          if (at + ply_size(p.count_type) > data.size())
            throw Error(fmt::format("{}: truncated in element \"{}\"", name, elements[e].name));
          const double c = load_binary(p.count_type, bytes + at, swap);
          if (!(c >= 0)) throw Error(fmt::format("{}: negative list length in element \"{}\"", name, elements[e].name));
          at += ply_size(p.count_type);
          // a count (of a float type, say) beyond what the bytes left can hold is refused before it is
          // converted: 1e25 has no 64-bit integer value
          if (c > static_cast<double>((data.size() - at) / ply_size(p.type)))
            throw Error(fmt::format("{}: truncated in element \"{}\"", name, elements[e].name));
          n = static_cast<std::uint64_t>(c);
        }
        if (n > (data.size() - at) / ply_size(p.type))
          throw Error(fmt::format("{}: truncated in element \"{}\"", name, elements[e].name));
        at += n * ply_size(p.type);
      }
  }
  std::size_t stride = 0;
  for (const PlyProperty& p : vertex.properties) {
    if (p.list) throw Error(fmt::format("{}: list properties in vertices are not supported", name));
    stride += ply_size(p.type);
  }
  if (stride == 0 || vertex.count > (data.size() - at) / stride)
    throw Error(
        fmt::format("{}: declares {} vertices of {} bytes but holds only {} bytes (truncated, or a wrong count)", name,
                    vertex.count, stride, data.size() - at));
  reserve(vertex.count);
  for (std::uint64_t v = 0; v < vertex.count; ++v) {
    for (std::size_t k = 0; k < vertex.properties.size(); ++k) {
      values[k] = load_binary(vertex.properties[k].type, bytes + at, swap);
      at += ply_size(vertex.properties[k].type);
    }
    store(v);
  }
  return raw;
}

// ---- checks ----

PointCloud checked(RawCloud raw, const std::string& name, double spacing) {
  const std::size_t n = raw.X.size();
  if (n == 0) throw Error(fmt::format("{}: the file holds no points", name));
  if (n > static_cast<std::size_t>(std::numeric_limits<index_t>::max() / 2))
    throw Error(fmt::format("{}: too many points", name));
  for (std::size_t i = 0; i < n; ++i) {
    if (!raw.X[i].allFinite()) throw Error(fmt::format("{}: point {}: a coordinate is not finite", name, i));
    if (raw.X[i].cwiseAbs().maxCoeff() > implausible)
      throw Error(fmt::format("{}: point {}: coordinate {:.3g} m is implausible (wrong endianness or units?)", name, i,
                              raw.X[i].cwiseAbs().maxCoeff()));
    // within a millionth to a million cells of the spacing: 1e-320 and 1e307 m^3 were taken, and the run then
    // "diverged" (issue 52)
    const double cell = spacing * spacing * spacing;
    if (!raw.volume.empty() && !(raw.volume[i] >= 1e-6 * cell && raw.volume[i] <= 1e6 * cell))
      throw Error(
          fmt::format("{}: point {}: volume {:.3g} m^3 is out of range: must lie in [{:.3g}, {:.3g}] m^3 "
                      "(1e-6 to 1e6 times spacing^3)",
                      name, i, raw.volume[i], 1e-6 * cell, 1e6 * cell));
  }
  if (n < 4)
    throw Error(fmt::format("{}: {} points are no solid (4 or more, not all on a plane, are needed)", name, n));
  PointCloud cloud;
  cloud.spacing = spacing;
  cloud.X.resize(3, static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) cloud.X.col(static_cast<Eigen::Index>(i)) = raw.X[i];
  // degenerate: the spread across the thinnest direction against the widest
  const Vec3 mean = cloud.X.rowwise().mean();
  const Points centred = cloud.X.colwise() - mean;
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(centred * centred.transpose() / static_cast<double>(n));
  const Vec3 spread = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  if (!(spread[0] > 1e-6 * spread[2]))
    throw Error(fmt::format("{}: the points lie on a {} (spread {:.3g} m across it): no solid to simulate", name,
                            spread[1] > 1e-6 * spread[2] ? "plane" : "line", spread[0]));
  // duplicates: nearest neighbours closer than a millionth of the spacing
  const double tiny = 1e-6 * (spacing > 0 ? spacing : spread[2]);
  const std::vector<index_t> nearest = nearest_neighbour(cloud.X);
  std::size_t duplicates = 0;
  index_t first = -1;
  for (index_t i = 0; i < static_cast<index_t>(n); ++i)
    if (nearest[static_cast<std::size_t>(i)] >= 0 &&
        (cloud.X.col(i) - cloud.X.col(nearest[static_cast<std::size_t>(i)])).norm() <= tiny) {
      ++duplicates;
      if (first < 0) first = i;
    }
  if (duplicates > 0)
    throw Error(
        fmt::format("{}: {} points coincide with another (first: point {} and point {} at ({:.6g}, {:.6g}, {:.6g}) m)",
                    name, duplicates, first, nearest[static_cast<std::size_t>(first)], cloud.X(0, first),
                    cloud.X(1, first), cloud.X(2, first)));
  cloud.volume = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(n), spacing * spacing * spacing);
  if (!raw.volume.empty())
    cloud.volume = Eigen::Map<const Eigen::VectorXd>(raw.volume.data(), static_cast<Eigen::Index>(n));
  cloud.surface.assign(n, 0);
  cloud.held = std::move(raw.held);
  return cloud;
}

}  // namespace

PointCloud parse_point_cloud(std::string_view data, std::string_view format, const std::string& name, double spacing) {
  const std::string ext = lower(format);
  RawCloud raw;
  if (ext == ".ply") raw = parse_ply(data, name);
  else if (ext == ".xyz" || ext == ".txt") raw = parse_text(data, false, name);
  else if (ext == ".csv") raw = parse_text(data, true, name);
  else
    throw Error(
        fmt::format("{}: format \"{}\" is not a point cloud this version reads (.ply .xyz .csv .txt)", name, format));
  return checked(std::move(raw), name, spacing);
}

PointCloud point_cloud_from_positions(const Points& X, const std::string& name, double spacing) {
  RawCloud raw;
  raw.X.reserve(static_cast<std::size_t>(X.cols()));
  for (Eigen::Index i = 0; i < X.cols(); ++i) raw.X.push_back(X.col(i));
  return checked(std::move(raw), name, spacing);
}

PointCloud read_point_cloud(const std::string& path, double spacing) {
  const std::string ext = file_extension(path);
  const auto size = check_input_file(path, "point cloud file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open the point cloud file", path));
  std::string data(size, '\0');
  in.read(data.data(), static_cast<std::streamsize>(size));
  if (!in) throw Error(fmt::format("{}: reading the point cloud file failed", path));
  return parse_point_cloud(data, ext, path, spacing);
}

}  // namespace pointhaptics
