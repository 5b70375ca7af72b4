#include <pointhaptics/io/scene_toml.hpp>

#include <pointhaptics/core/error.hpp>
#include <pointhaptics/io/input_file.hpp>

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace pointhaptics {

namespace {

struct Context {
  std::string file;
  std::string base_dir;
  const std::vector<SceneSetting>* settings = nullptr;
};

// toml++ recurses once per level of a dotted key or table header (a.b.c = 1, [a.b.c]), and some ten
// thousand levels overflow the stack (issue 21: a segfault); no scene needs more than a few. So before
// parsing, every chain of dot-separated keys (bare or quoted, outside strings and comments) is counted.
void check_key_nesting(std::string_view text, const std::string& name) {
  constexpr int max_levels = 64;
  int line = 1, dots = 0, chain_line = 1;
  const auto bare = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      // a string (a quoted key, or a value): skipped whole, multi-line ones too; the chain goes on
      const bool multi = text.substr(i, 3) == std::string(3, c);
      const std::size_t open = multi ? 3 : 1;
      std::size_t j = i + open;
      for (; j < text.size(); ++j) {
        if (c == '"' && text[j] == '\\') {
          ++j;
          continue;
        }
        if (text[j] == '\n') {
          if (!multi) break;
          ++line;
        }
        if (multi ? text.substr(j, 3) == std::string(3, c) : text[j] == c) break;
      }
      i = j + open - 1;
      continue;
    }
    if (c == '#') {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
      continue;
    }
    if (c == '.') {
      if (dots++ == 0) chain_line = line;
      if (dots > max_levels)
        throw Error(
            fmt::format("{}:{}: a key or table header nested more than {} levels deep", name, chain_line, max_levels));
      continue;
    }
    if (bare(c) || c == ' ' || c == '\t') continue;
    dots = 0;  // '=', ']', ',', a newline ...: the chain ends
    if (c == '\n') ++line;
  }
}

// the source name of the values a SceneSetting puts into a scene (their line is the setting's own)
constexpr std::string_view setting_source = "<scene setting>";

[[noreturn]] void fail(const Context& ctx, const toml::source_region& where, std::string_view key,
                       std::string_view what) {
  // a key set from outside the file has no line in it: its message names the setting instead
  const bool set = where.begin.line == 0 || (where.path && *where.path == setting_source);
  if (set && ctx.settings) {
    std::string dotted(key);  // load[0].total -> load.0.total, as the setting spells it
    std::replace(dotted.begin(), dotted.end(), '[', '.');
    std::erase(dotted, ']');
    for (const SceneSetting& s : *ctx.settings)
      if (s.key == dotted) throw Error(fmt::format("{}: {} (set to {}): {}", ctx.file, key, s.value, what));
    for (const SceneSetting& s : *ctx.settings)
      if (s.key.starts_with(dotted + "."))
        throw Error(fmt::format("{}: {} (made for the setting {}={}): {}", ctx.file, key, s.key, s.value, what));
  }
  throw Error(fmt::format("{}:{}: {}: {}", ctx.file, where.begin.line, key, what));
}

// The value of a setting as a TOML node (in a table of its own, under "value"); a bare word that TOML does
// not read (neo_hookean) is a string.
toml::table setting_value(const SceneSetting& s, const std::string& file) {
  try {
    return toml::parse("value = " + s.value, setting_source);
  } catch (const toml::parse_error&) {}
  const bool word = !s.value.empty() && std::all_of(s.value.begin(), s.value.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/';
  });
  if (!word)
    throw Error(
        fmt::format("{}: {} (set to {}): not a TOML value (a number, true or false, [x, y, z], or a \"string\")", file,
                    s.key, s.value));
  toml::table t;
  t.insert("value", s.value);
  return t;
}

// Puts one setting into the parsed scene: the tables on its path are made when missing, an array of tables
// takes an index ("load.0.total").
void apply_setting(toml::table& root, const SceneSetting& s, const std::string& file) {
  std::vector<std::string> parts;
  for (std::size_t begin = 0;;) {
    const std::size_t dot = s.key.find('.', begin);
    parts.push_back(s.key.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin));
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  const auto bad = [&](std::string_view what) -> Error {
    return Error(fmt::format("{}: {} (set to {}): {}", file, s.key, s.value, what));
  };
  for (const std::string& part : parts)
    if (part.empty()) throw bad("an empty key on the path (expected section.key, e.g. material.young)");
  toml::table value = setting_value(s, file);
  toml::node* at = &root;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::string& part = parts[k];
    const bool last = k + 1 == parts.size();
    if (toml::table* table = at->as_table()) {
      if (last) {
        value.get("value")->visit([&](auto& v) { table->insert_or_assign(part, std::move(v)); });
        return;
      }
      if (!table->get(part)) table->insert(part, toml::table{});
      at = table->get(part);
    } else if (toml::array* array = at->as_array()) {
      std::size_t index = 0;
      const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), index);
      if (error != std::errc() || end != part.data() + part.size() || index >= array->size())
        throw bad(fmt::format("\"{}\" is not an index of the array (it has {} entries)", part, array->size()));
      if (last) {
        value.get("value")->visit(
            [&](auto& v) { array->replace(array->cbegin() + static_cast<std::ptrdiff_t>(index), std::move(v)); });
        return;
      }
      at = array->get(index);
    } else {
      throw bad(fmt::format("\"{}\" is a value, not a table", parts[k - 1]));
    }
  }
}

// Reads the keys of one table, remembering which it read, so that the rest can be reported as unknown.
class TableReader {
 public:
  TableReader(const Context& ctx, const toml::table& table, std::string section)
      : ctx_(ctx), table_(table), section_(std::move(section)) {}

  std::string name(std::string_view key) const {
    return section_.empty() ? std::string(key) : section_ + "." + std::string(key);
  }
  const toml::node* find(std::string_view key) {
    seen_.insert(std::string(key));
    return table_.get(key);
  }
  [[noreturn]] void fail_at(const toml::node& node, std::string_view key, std::string_view what) const {
    fail(ctx_, node.source(), name(key), what);
  }
  [[noreturn]] void fail_table(std::string_view key, std::string_view what) const {
    fail(ctx_, table_.source(), name(key), what);
  }

  double number(std::string_view key, double fallback) {
    const toml::node* node = find(key);
    return node ? as_number(*node, key) : fallback;
  }
  double as_number(const toml::node& node, std::string_view key) const {
    double value;
    if (auto f = node.as_floating_point()) value = f->get();
    else if (auto i = node.as_integer()) value = static_cast<double>(i->get());
    else fail_at(node, key, fmt::format("expected a number, got {}", type_name(node)));
    if (!std::isfinite(value)) fail_at(node, key, fmt::format("{} is not a finite number", value));
    return value;
  }
  // number with a range rule: ok(value) must hold
  template <class Ok>
  double number(std::string_view key, double fallback, Ok ok, std::string_view rule) {
    const toml::node* node = find(key);
    if (!node) return fallback;
    const double value = as_number(*node, key);
    if (!ok(value)) fail_at(*node, key, fmt::format("{} is out of range: {}", value, rule));
    return value;
  }
  long long integer(std::string_view key, long long fallback) {
    const toml::node* node = find(key);
    if (!node) return fallback;
    if (auto i = node->as_integer()) return i->get();
    fail_at(*node, key, fmt::format("expected an integer, got {}", type_name(*node)));
  }
  Vec3 vec3(std::string_view key, const Vec3& fallback) {
    const toml::node* node = find(key);
    return node ? as_vec3(*node, key) : fallback;
  }
  Vec3 as_vec3(const toml::node& node, std::string_view key) const {
    const toml::array* array = node.as_array();
    if (!array || array->size() != 3) fail_at(node, key, "expected an array of 3 numbers [x, y, z]");
    Vec3 v;
    for (int a = 0; a < 3; ++a) v[a] = as_number(*array->get(a), key);
    // positions (m), forces (N), accelerations (m/s^2): beyond 1e9 no scene of this library means it
    if (!(v.cwiseAbs().maxCoeff() <= 1e9))
      fail_at(node, key,
              fmt::format("[{}, {}, {}] is out of range: each value must lie in [-1e9, 1e9]", v.x(), v.y(), v.z()));
    return v;
  }
  bool boolean(std::string_view key, bool fallback) {
    const toml::node* node = find(key);
    if (!node) return fallback;
    if (auto b = node->as_boolean()) return b->get();
    fail_at(*node, key, fmt::format("expected true or false, got {}", type_name(*node)));
  }
  std::string string(std::string_view key, std::string fallback) {
    const toml::node* node = find(key);
    if (!node) return fallback;
    if (auto s = node->as_string()) return s->get();
    fail_at(*node, key, fmt::format("expected a string, got {}", type_name(*node)));
  }
  // a string that must be one of `choices`
  std::string choice(std::string_view key, std::string fallback, std::initializer_list<std::string_view> choices) {
    const toml::node* node = table_.get(key);
    std::string value = string(key, std::move(fallback));
    for (auto c : choices)
      if (value == c) return value;
    std::string list;
    for (auto c : choices) list += (list.empty() ? "" : " | ") + std::string(c);
    fail_at(*node, key, fmt::format("unknown value \"{}\" (expected {})", value, list));
  }
  // a string naming a value of enum E (its table in core/parameters.hpp)
  template <class E>
  E enumeration(std::string_view key, E fallback) {
    const toml::node* node = table_.get(key);
    const std::string value = string(key, std::string(enum_name(fallback)));
    if (const std::optional<E> e = parse_enum<E>(value)) return *e;
    fail_at(*node, key, fmt::format("unknown value \"{}\" (expected {})", value, enum_choices<E>()));
  }
  const toml::table* subtable(std::string_view key) {
    const toml::node* node = find(key);
    if (!node) return nullptr;
    if (auto t = node->as_table()) return t;
    fail_at(*node, key, fmt::format("expected a table, got {}", type_name(*node)));
  }
  Aabb box(std::string_view key, bool required) {
    const toml::table* t = subtable(key);
    if (!t) {
      if (required) fail_table(key, "missing (expected box = { min = [x, y, z], max = [x, y, z] })");
      return {};
    }
    TableReader r(ctx_, *t, name(key));
    Aabb b;
    if (!t->get("min") || !t->get("max")) r.fail_table("min", "a box needs both min and max");
    b.min = r.vec3("min", Vec3::Zero());
    b.max = r.vec3("max", Vec3::Zero());
    r.finish();
    if (!(b.min.array() <= b.max.array()).all())
      fail(ctx_, t->source(), name(key), "min must not exceed max in any component");
    return b;
  }
  // every key not read is unknown
  void finish() const {
    for (auto&& [key, node] : table_)
      if (!seen_.count(std::string(key.str())))
        fail(ctx_, key.source().begin.line ? key.source() : node.source(), name(key.str()), "unknown key");
  }
  int line() const { return static_cast<int>(table_.source().begin.line); }
  const Context& context() const { return ctx_; }

  static std::string_view type_name(const toml::node& node) {
    switch (node.type()) {
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a float";
      case toml::node_type::boolean: return "a boolean";
      case toml::node_type::array: return "an array";
      case toml::node_type::table: return "a table";
      default: return "a date or time";
    }
  }

 private:
  const Context& ctx_;
  const toml::table& table_;
  std::string section_;
  std::set<std::string> seen_;
};

// Every number has a finite range, named in its message (issue 52: a probe stiffness of 1e300 was accepted and
// made a "converged" solve carry 3.1e9 N): (0, hi] or [0, hi]
auto positive_up_to(double hi) {
  return [hi](double x) { return x > 0 && x <= hi; };
}
auto non_negative_up_to(double hi) {
  return [hi](double x) { return x >= 0 && x <= hi; };
}

void read_object(TableReader& r, ObjectSpec& o, const Context& ctx) {
  o.shape = r.enumeration("shape", o.shape);
  o.spacing = r.number("spacing", o.spacing, positive_up_to(100), "must lie in (0, 100] (m)");
  o.surface_edge = r.number(
      "surface_edge", o.surface_edge, [&](double e) { return e > 0 && e >= 1e-3 * o.spacing; },
      "must be > 0 (m) and at least a thousandth of the spacing");
  if (o.shape == ShapeKind::BOX) {
    if (!r.find("size")) r.fail_table("size", "a box needs size = [lx, ly, lz] (m)");
    o.size = r.vec3("size", o.size);
    if (!(o.size.array() > 0).all()) r.fail_at(*r.find("size"), "size", "every edge length must be > 0 (m)");
  }
  o.origin = r.vec3("origin", o.origin);
  // far from 0 the points' coordinates lose the digits that tell them apart (1e17 m put them on each other)
  if (!(o.origin.cwiseAbs().maxCoeff() <= 1e6))
    r.fail_at(*r.find("origin"), "origin",
              fmt::format("[{}, {}, {}] is out of range: each value must lie in [-1e6, 1e6] (m; farther out a double "
                          "cannot tell points a spacing apart)",
                          o.origin.x(), o.origin.y(), o.origin.z()));
  if (o.shape == ShapeKind::SPHERE || o.shape == ShapeKind::HALF_SPHERE) {
    if (!r.find("radius")) r.fail_table("radius", "a sphere needs radius = <m>");
  }
  if (o.shape == ShapeKind::SPHERE || o.shape == ShapeKind::HALF_SPHERE)
    o.radius = r.number("radius", o.radius, positive_up_to(1e3), "must lie in (0, 1e3] (m)");
  if (o.shape == ShapeKind::FILE) {
    if (!r.find("file")) r.fail_table("file", "shape = \"file\" needs file = \"path\"");
    o.file = r.string("file", "");
    std::filesystem::path p(o.file);
    if (p.is_relative()) p = std::filesystem::path(ctx.base_dir) / p;
    o.file = p.lexically_normal().string();
    if (const toml::node* node = r.find("threshold")) {
      const toml::array* a = node->as_array();
      if (!a || a->size() != 2) r.fail_at(*node, "threshold", "expected [low, high] (image intensities)");
      o.threshold_low = r.as_number(*a->get(0), "threshold");
      o.threshold_high = r.as_number(*a->get(1), "threshold");
      if (!(o.threshold_low <= o.threshold_high)) r.fail_at(*node, "threshold", "low must not exceed high");
    }
  }
  // any shape: the scene builder says when there is no volume image to map
  if (const toml::node* node = r.find("stiffness_map")) {
    const toml::array* rows = node->as_array();
    const char* form =
        "expected [[intensity, young], ...] with at least two rows, intensities increasing, young in (0, 1e13] Pa";
    if (!rows || rows->size() < 2) r.fail_at(*node, "stiffness_map", form);
    for (const toml::node& row : *rows) {
      const toml::array* pair = row.as_array();
      if (!pair || pair->size() != 2) r.fail_at(row, "stiffness_map", form);
      const double intensity = r.as_number(*pair->get(0), "stiffness_map"),
                   young = r.as_number(*pair->get(1), "stiffness_map");
      if (!(young > 0 && young <= 1e13) || (!o.stiffness_map.empty() && !(intensity > o.stiffness_map.back()[0])))
        r.fail_at(row, "stiffness_map", form);
      o.stiffness_map.push_back({intensity, young});
    }
  }
  o.line = r.line();
}

// the material keys a [material] table and a [[region]] share, with their ranges
double read_young(TableReader& r, double fallback) {
  // beyond any solid (steel is 2e11 Pa, air 1.2 kg/m^3): 1e300 Pa or 1e-320 kg/m^3 made the solver "diverge"
  return r.number(
      "young", fallback, [](double x) { return x > 0 && x <= 1e13; }, "must lie in (0, 1e13] (Pa)");
}
double read_poisson(TableReader& r, double fallback) {
  return r.number(
      "poisson", fallback, [](double x) { return x > -1 && x < 0.5; }, "must lie in (-1, 0.5)");
}
double read_density(TableReader& r, double fallback) {
  return r.number(
      "density", fallback, [](double x) { return x >= 1e-3 && x <= 1e5; }, "must lie in [1e-3, 1e5] (kg/m^3)");
}

// Mooney-Rivlin's c10, c01 and bulk (Pa), all three, instead of young and poisson, which are set from them
// (mu = 2 (c10 + c01), K = bulk: E = 9 K mu / (3 K + mu), nu = (3 K - 2 mu) / (2 (3 K + mu)))
void read_mooney_rivlin(TableReader& r, MaterialParams& m) {
  const bool any = r.find("c10") || r.find("c01") || r.find("bulk");
  if (!any) return;
  const char* first = r.find("c10") ? "c10" : r.find("c01") ? "c01" : "bulk";
  if (m.model != MaterialModel::MOONEY_RIVLIN)
    r.fail_at(*r.find(first), first,
              "c10, c01 and bulk are Mooney-Rivlin's: set model = \"mooney_rivlin\" (or give young and poisson)");
  if (!r.find("c10") || !r.find("c01") || !r.find("bulk"))
    r.fail_table(first, "give all of c10, c01 and bulk (Pa), or young and poisson");
  if (r.find("young") || r.find("poisson"))
    r.fail_at(*r.find(r.find("young") ? "young" : "poisson"), r.find("young") ? "young" : "poisson",
              "give either young and poisson or c10, c01 and bulk, not both");
  m.c10 = r.number("c10", 0.0, non_negative_up_to(1e13), "must lie in [0, 1e13] (Pa)");
  m.c01 = r.number("c01", 0.0, non_negative_up_to(1e13), "must lie in [0, 1e13] (Pa)");
  const double bulk = r.number("bulk", 0.0, positive_up_to(1e14), "must lie in (0, 1e14] (Pa)");
  const double mu = 2 * (m.c10 + m.c01);
  if (!(mu > 0)) r.fail_at(*r.find("c10"), "c10", "c10 + c01 must be > 0 (Pa)");
  m.young = 9 * bulk * mu / (3 * bulk + mu);
  m.poisson = (3 * bulk - 2 * mu) / (2 * (3 * bulk + mu));
}

// prony = [[g, tau], ...]: the relaxing shares of the shear modulus and their times (viscoelasticity.hpp)
void read_prony(TableReader& r, MaterialParams& m) {
  const toml::node* node = r.find("prony");
  if (!node) return;
  const toml::array* rows = node->as_array();
  if (!rows || rows->empty() || rows->size() > max_prony_terms) r.fail_at(*node, "prony", prony_rule);
  m.prony.clear();
  for (const toml::node& row : *rows) {
    const toml::array* pair = row.as_array();
    if (!pair || pair->size() != 2) r.fail_at(row, "prony", prony_rule);
    m.prony.push_back({r.as_number(*pair->get(0), "prony"), r.as_number(*pair->get(1), "prony")});
    if (!valid_prony(m.prony)) r.fail_at(row, "prony", prony_rule);  // the row that breaks it
  }
}

void read_material(TableReader& r, MaterialParams& m) {
  m.model = r.enumeration("model", m.model);  // the registry: mechanics/energies/material.hpp
  m.young = read_young(r, m.young);
  m.poisson = read_poisson(r, m.poisson);
  m.density = read_density(r, m.density);
  read_mooney_rivlin(r, m);
  m.volume_stiffness = r.number(
      "volume_stiffness", m.volume_stiffness, [](double x) { return x >= 0 && x <= 1e13; },
      "must lie in [0, 1e13] (Pa)");
  m.damping = r.number("damping", m.damping, non_negative_up_to(1e6), "must lie in [0, 1e6] (1/s)");
  m.hourglass = r.number(
      "hourglass", m.hourglass, [](double x) { return x >= 0 && x <= 10; }, "must lie in [0, 10]");
  m.volume = r.enumeration("volume", m.volume);
  read_prony(r, m);
}

void read_kernel(TableReader& r, KernelParams& k) {
  k.type = r.enumeration("type", k.type);
  if (r.find("support_factor") && r.find("support"))
    r.fail_at(*r.find("support"), "support", "give either support (m) or support_factor, not both");
  k.support_factor = r.number(
      "support_factor", k.support_factor, [](double x) { return x > 1 && x <= 20; }, "must lie in (1, 20]");
  k.support = r.number("support", 0.0, positive_up_to(1e3), "must lie in (0, 1e3] (m)");
}

void read_solver(TableReader& r, SolverSpec& s) {
  s.kind = r.enumeration("kind", s.kind);
  s.dt = r.number(
      "dt", s.dt, [](double x) { return x >= 1e-9 && x <= 1; }, "must lie in [1e-9, 1] (s)");
  s.duration = r.number(
      "duration", s.duration, [](double x) { return x >= 0 && x <= 1e6; }, "must lie in [0, 1e6] (s)");
  s.tolerance = r.number(
      "tolerance", s.tolerance, [](double x) { return x >= 1e-12 && x <= 1e-2; },
      "must lie in [1e-12, 0.01] (a relative residual: below 1e-12 double precision cannot reach it, above 0.01 it is no equilibrium)");
  auto count = [&](std::string_view key, int fallback, int lo, int hi) {
    const auto node = r.find(key);
    const long long v = r.integer(key, fallback);
    if (v < lo || v > hi) r.fail_at(*node, key, fmt::format("must lie in [{}, {}]", lo, hi));
    return static_cast<int>(v);
  };
  s.max_iterations = count("max_iterations", s.max_iterations, 1, 100000);
  s.max_cg_iterations = count("max_cg_iterations", s.max_cg_iterations, 1, 10000000);
  s.iteration_budget = count("iteration_budget", s.iteration_budget, 0, 1000);
  s.preconditioner = r.enumeration("preconditioner", s.preconditioner);
  s.refactor_iterations = count("refactor_iterations", s.refactor_iterations, 1, 1000);
  s.refactorisation = r.enumeration("refactorisation", s.refactorisation);
  s.sleep = r.boolean("sleep", s.sleep);
}

std::string resolve(const Context& ctx, const std::string& file);

void read_reduction(TableReader& r, const Context& ctx, ReductionSpec& s) {
  const auto node = r.find("modes");
  if (!node) r.fail_table("modes", "missing: the reduced basis' size, modes = r (e.g. 20)");
  const long long modes = r.integer("modes", 0);
  if (modes < 1 || modes > 200) r.fail_at(*node, "modes", "must lie in [1, 200]");
  s.modes = static_cast<int>(modes);
  s.basis_spacing = r.number("basis_spacing", 0.0, positive_up_to(1e3), "must lie in (0, 1e3] (m)");
  if (const auto rings = r.find("contact_rings")) {
    const long long n = r.integer("contact_rings", s.contact_rings);
    if (n < 1 || n > 20) r.fail_at(*rings, "contact_rings", "must lie in [1, 20] (neighbour rings)");
    s.contact_rings = static_cast<int>(n);
  }
  // the basis' source and the forces' evaluation: one of each is built so far, the others are named
  if (r.choice("basis", "modal", {"modal", "snapshots"}) != "modal")
    r.fail_at(*r.find("basis"), "basis",
              "\"snapshots\" (proper orthogonal decomposition) is not built yet: use \"modal\"");
  if (r.choice("forces", "polynomial", {"polynomial", "hyper"}) != "polynomial")
    r.fail_at(*r.find("forces"), "forces",
              "\"hyper\" (integration points for any material) is not built yet: use \"polynomial\" (St. "
              "Venant-Kirchhoff)");
  // where the basis is kept between runs: "auto" (the user's cache folder), "none", or a folder (relative to the
  // scene file)
  const std::string cache = r.string("cache", "auto");
  if (cache.empty()) r.fail_at(*r.find("cache"), "cache", "give \"auto\", \"none\" or a folder");
  s.cache = cache == "none" ? std::string() : cache == "auto" ? cache : resolve(ctx, cache);
}

// box = { min, max }, sphere = { centre, radius } or cylinder = { centre, axis, radius, half_length }: exactly one
void read_selector(TableReader& r, PointSelector& f) {
  const int selectors = (r.find("box") != nullptr) + (r.find("sphere") != nullptr) + (r.find("cylinder") != nullptr);
  if (selectors != 1)
    r.fail_table("box",
                 "give exactly one of box = { min, max }, sphere = { centre, radius } or "
                 "cylinder = { centre, axis, radius, half_length } (m)");
  if (r.find("box")) f.box = r.box("box", true);
  if (const toml::table* t = r.subtable("sphere")) {
    TableReader s(r.context(), *t, r.name("sphere"));
    if (!t->get("centre") || !t->get("radius"))
      s.fail_table("centre", "a sphere needs centre = [x, y, z] and radius (m)");
    f.sphere = SphereRegion{s.vec3("centre", Vec3::Zero()),
                            s.number("radius", 0.0, positive_up_to(1e3), "must lie in (0, 1e3] (m)")};
    s.finish();
  }
  if (const toml::table* t = r.subtable("cylinder")) {
    TableReader c(r.context(), *t, r.name("cylinder"));
    for (const char* key : {"centre", "axis", "radius", "half_length"})
      if (!t->get(key)) c.fail_table(key, "a cylinder needs centre, axis, radius and half_length (m)");
    CylinderRegion cyl;
    cyl.centre = c.vec3("centre", cyl.centre);
    const Vec3 axis = c.vec3("axis", cyl.axis);
    if (!(axis.norm() > 0)) c.fail_at(*t->get("axis"), "axis", "must not be zero");
    cyl.axis = axis.normalized();
    cyl.radius = c.number("radius", 0.0, positive_up_to(1e3), "must lie in (0, 1e3] (m)");
    cyl.half_length = c.number("half_length", 0.0, positive_up_to(1e3), "must lie in (0, 1e3] (m)");
    c.finish();
    f.cylinder = cyl;
  }
}

// [[object]]: an [object] table's keys, a name and an optional material = { ... } over the scene's [material]
BodySpec read_body(TableReader& r, const MaterialParams& scene_material, const Context& ctx) {
  BodySpec b;
  b.name = r.string("name", "");
  if (b.name.empty())
    r.fail_table("name", "an [[object]] needs a name = \"...\" (with several objects, its outputs are keyed by it)");
  read_object(r, b.object, ctx);
  b.material = scene_material;
  if (const toml::table* t = r.subtable("material")) {
    TableReader m(r.context(), *t, r.name("material"));
    read_material(m, b.material);
    m.finish();
  }
  return b;
}

// [contact]: friction = mu between any two bodies, and pairs = [{ bodies = ["a", "b"], friction = mu }, ...]
void read_contact(TableReader& r, ContactSpec& c) {
  c.line = r.line();
  c.friction = r.number("friction", c.friction, non_negative_up_to(10), "must lie in [0, 10]");
  const toml::node* node = r.find("pairs");
  if (!node) return;
  const toml::array* pairs = node->as_array();
  const char* form = "expected [{ bodies = [\"NAME\", \"NAME\"], friction = mu }, ...]";
  if (!pairs) r.fail_at(*node, "pairs", form);
  for (std::size_t k = 0; k < pairs->size(); ++k) {
    const toml::table* t = pairs->get(k)->as_table();
    if (!t) r.fail_at(*pairs->get(k), "pairs", form);
    TableReader p(r.context(), *t, fmt::format("{}[{}]", r.name("pairs"), k));
    ContactSpec::Pair pair;
    const toml::node* names = p.find("bodies");
    const toml::array* two = names ? names->as_array() : nullptr;
    if (!two || two->size() != 2 || !two->get(0)->as_string() || !two->get(1)->as_string())
      p.fail_table("bodies", "expected bodies = [\"NAME\", \"NAME\"] (two [[object]] names)");
    pair.bodies = {two->get(0)->as_string()->get(), two->get(1)->as_string()->get()};
    if (!t->get("friction")) p.fail_table("friction", "missing (Coulomb's coefficient between the two bodies)");
    pair.friction = p.number("friction", 0.0, non_negative_up_to(10), "must lie in [0, 10]");
    p.finish();
    c.pairs.push_back(pair);
  }
}

FixedSpec read_fixed(TableReader& r) {
  FixedSpec f;
  f.line = r.line();
  f.object = r.string("object", "");
  read_selector(r, f);
  f.displacement = r.vec3("displacement", f.displacement);
  f.ramp = r.number("ramp", 0.0, non_negative_up_to(1e6), "must lie in [0, 1e6] (s)");
  return f;
}

RegionSpec read_region(TableReader& r) {
  RegionSpec g;
  g.line = r.line();
  g.object = r.string("object", "");
  read_selector(r, g);
  if (r.find("model")) g.model = r.enumeration("model", MaterialModel::SVK);
  if (r.find("young")) g.young = read_young(r, 0);
  if (r.find("poisson")) g.poisson = read_poisson(r, 0);
  if (r.find("density")) g.density = read_density(r, 0);
  return g;
}

// `scene`'s [object], or the [[object]] the table names (an unknown name is check_body_names()'s to report)
RefineSpec read_refine(TableReader& r, const Scene& scene) {
  RefineSpec f;
  f.line = r.line();
  f.object = r.string("object", "");
  const auto named = std::find_if(scene.bodies.begin(), scene.bodies.end(),
                                  [&](const BodySpec& b) { return !f.object.empty() && b.name == f.object; });
  const ObjectSpec& object = named != scene.bodies.end() ? named->object : scene.object;
  read_selector(r, f);
  if (!r.find("spacing")) r.fail_table("spacing", "a [[refine]] table needs spacing = s (m), finer than the object's");
  f.spacing = r.number(
      "spacing", 0.0, [&](double s) { return s > 0 && s < object.spacing && s >= 0.05 * object.spacing; },
      fmt::format("must be finer than {}'s spacing ({} m), and at least a twentieth of it (m)",
                  f.object.empty() ? std::string("the object") : "object \"" + f.object + "\"", object.spacing));
  if (object.shape == ShapeKind::FILE)
    r.fail_table("spacing", "[[refine]] is for box, sphere and half_sphere objects (not files)");
  return f;
}

CutSpec read_cut(TableReader& r) {
  CutSpec c;
  c.line = r.line();
  auto segment = [&](std::string_view key) {
    const toml::node* node = r.find(key);
    const toml::array* ends = node ? node->as_array() : nullptr;
    if (!ends || ends->size() != 2)
      r.fail_table(
          key,
          "a [[cut]] needs edge = [[x, y, z], [x, y, z]] (the blade's edge, m) and to = [[x, y, z], [x, y, z]] (where it ends)");
    return std::array<Vec3, 2>{r.as_vec3(*ends->get(0), key), r.as_vec3(*ends->get(1), key)};
  };
  c.edge = segment("edge");
  c.to = segment("to");
  if ((c.edge[1] - c.edge[0]).norm() == 0 || (c.to[1] - c.to[0]).norm() == 0)
    r.fail_table("edge", "the blade's edge has zero length (its two ends coincide)");
  c.start = r.number(
      "start", c.start, [](double t) { return t >= 0 && t <= 1e6; }, "must lie in [0, 1e6] (s)");
  c.duration = r.number(
      "duration", c.duration, [](double t) { return t >= 0 && t <= 1e6; }, "must lie in [0, 1e6] (s)");
  c.object = r.string("object", "");
  return c;
}

// keyframes = [[t, a, b, c], ...] of a body the scene poses (an obstacle's translation, a tool's position): times
// increasing from 0 s within 1e6 s, values within 1e6 m; `form` and `what` name them in the errors. Empty without
// the key.
// `fifth`: each keyframe has a fifth value (a grasper's opening, m, in [0, 1]), put there
std::vector<std::array<double, 4>> read_posed_keyframes(TableReader& r, std::string_view form, std::string_view what,
                                                        std::vector<double>* fifth = nullptr) {
  std::vector<std::array<double, 4>> frames;
  const toml::node* node = r.find("keyframes");
  if (!node) return frames;
  const toml::array* rows = node->as_array();
  if (!rows || rows->empty()) r.fail_at(*node, "keyframes", fmt::format("expected keyframes = [{}, ...]", form));
  const std::size_t columns = fifth ? 5 : 4;
  for (const toml::node& row : *rows) {
    const toml::array* k = row.as_array();
    if (!k || k->size() != columns) r.fail_at(row, "keyframes", fmt::format("each keyframe is {} (s, m)", form));
    std::array<double, 4> frame{};
    for (std::size_t a = 0; a < 4; ++a) frame[a] = r.as_number(*k->get(a), "keyframes");
    if (fifth) {
      fifth->push_back(r.as_number(*k->get(4), "keyframes"));
      if (!(fifth->back() >= 0 && fifth->back() <= 1))
        r.fail_at(row, "keyframes", "a grasper's opening (the 5th value) must lie in [0, 1] (m)");
    }
    const double last_t = frames.empty() ? -1.0 : frames.back()[0];
    if (!(frame[0] > last_t) || frame[0] < 0 || frame[0] > 1e6)
      r.fail_at(row, "keyframes", "times must increase, from 0 s, and stay within 1e6 s");
    if (!(std::max({std::abs(frame[1]), std::abs(frame[2]), std::abs(frame[3])}) <= 1e6))
      r.fail_at(row, "keyframes", fmt::format("{} must lie within 1e6 m", what));
    frames.push_back(frame);
  }
  return frames;
}

// direction = [x, y, z]: the unit direction a tool held at a position presses in (only with position)
void read_press_direction(TableReader& r, ProbeSpec& p) {
  const toml::node* node = r.find("direction");
  if (!node) return;
  if (!r.find("position"))
    r.fail_at(*node, "direction", "only a tool held at a position (position = [x, y, z]) presses along a direction");
  const Vec3 d = r.as_vec3(*node, "direction");
  if (!(d.norm() > 1e-12)) r.fail_at(*node, "direction", "must not be zero (the direction the tool presses in)");
  p.direction = d.normalized();
}

// name = "...", exactly one of plane = { point, normal }, box = { min, max }, sphere = { centre, radius } or
// capsule = { ends = [[x, y, z], [x, y, z]], radius }, and friction
ObstacleSpec read_obstacle(TableReader& r) {
  ObstacleSpec o;
  o.line = r.line();
  o.name = r.string("name", "");
  if (o.name.empty()) r.fail_table("name", "an [[obstacle]] needs a name = \"...\" (its forces are reported by it)");
  const int shapes = (r.find("plane") != nullptr) + (r.find("box") != nullptr) + (r.find("sphere") != nullptr) +
                     (r.find("capsule") != nullptr);
  if (shapes != 1)
    r.fail_table("plane",
                 "give exactly one of plane = { point, normal }, box = { min, max }, sphere = { centre, "
                 "radius } or capsule = { ends = [[x, y, z], [x, y, z]], radius }");
  const auto radius_of = [](TableReader& t) {
    if (!t.find("radius")) t.fail_table("radius", "missing (m)");
    return t.number(
        "radius", 0.0, [](double x) { return x > 0 && x <= 1e6; }, "must lie in (0, 1e6] (m)");
  };
  if (const toml::table* t = r.subtable("plane")) {
    TableReader p(r.context(), *t, r.name("plane"));
    o.shape = ObstacleShape::PLANE;
    o.point = p.vec3("point", o.point);
    if (!p.find("normal")) p.fail_table("normal", "a plane needs normal = [x, y, z] (out of the obstacle)");
    const Vec3 normal = p.vec3("normal", o.normal);
    if (!(normal.norm() > 0)) p.fail_at(*p.find("normal"), "normal", "must not be zero");
    o.normal = normal.normalized();
    p.finish();
  } else if (r.find("box")) {
    o.shape = ObstacleShape::BOX;
    o.box = r.box("box", true);
    if (!((o.box.max - o.box.min).minCoeff() > 0)) r.fail_table("box", "the box has no volume (min = max somewhere)");
  } else if (const toml::table* t = r.subtable("sphere")) {
    TableReader p(r.context(), *t, r.name("sphere"));
    o.shape = ObstacleShape::SPHERE;
    o.centre = p.vec3("centre", o.centre);
    o.radius = radius_of(p);
    p.finish();
  } else if (const toml::table* t = r.subtable("capsule")) {
    TableReader p(r.context(), *t, r.name("capsule"));
    o.shape = ObstacleShape::CAPSULE;
    const toml::node* node = p.find("ends");
    const toml::array* ends = node ? node->as_array() : nullptr;
    if (!ends || ends->size() != 2) p.fail_table("ends", "a capsule needs ends = [[x, y, z], [x, y, z]] (its axis, m)");
    o.ends = {p.as_vec3(*ends->get(0), "ends"), p.as_vec3(*ends->get(1), "ends")};
    o.radius = radius_of(p);
    p.finish();
  }
  o.friction = r.number(
      "friction", o.friction, [](double mu) { return mu >= 0 && mu <= 10; }, "must lie in [0, 10]");
  o.keyframes = read_posed_keyframes(r, "[t, dx, dy, dz]", "a translation");
  return o;
}

LoadSpec read_load(TableReader& r) {
  LoadSpec l;
  l.line = r.line();
  l.object = r.string("object", "");
  l.kind = r.enumeration("kind", l.kind);
  if (l.kind == LoadKind::TRACTION) {
    l.box = r.box("box", true);
    if (!r.find("total")) r.fail_table("total", "a traction load needs total = [fx, fy, fz] (N)");
    l.total = r.vec3("total", l.total);
  } else if (l.kind == LoadKind::GRAVITY) {
    l.g = r.vec3("g", l.g);
  } else {
    if (!r.find("point")) r.fail_table("point", "a point load needs point = <index>");
    l.point = r.integer("point", 0);
    if (l.point < 0) r.fail_at(*r.find("point"), "point", "must be a point index >= 0");
    if (!r.find("force")) r.fail_table("force", "a point load needs force = [fx, fy, fz] (N)");
    l.force = r.vec3("force", l.force);
  }
  return l;
}

std::string resolve(const Context& ctx, const std::string& file) {
  std::filesystem::path p(file);
  if (p.is_relative()) p = std::filesystem::path(ctx.base_dir) / p;
  return p.lexically_normal().string();
}

// a tool's shape and its contact's settings: [probe]'s and a [[tool]]'s keys radius, shape, length, orientation,
// friction, surface_map and sample_spacing
void read_tool_shape(TableReader& r, ProbeSpec& p) {
  p.radius = r.number("radius", p.radius, positive_up_to(10), "must lie in (0, 10] (m)");
  const std::string shape = r.choice("shape", "sphere", {"sphere", "capsule", "grasper"});
  p.grasper = shape == "grasper";
  p.capsule = shape == "capsule" || p.grasper;  // a grasper's jaws are capsules
  p.length = r.number("length", p.length, non_negative_up_to(10), "must lie in [0, 10] (m)");
  if (p.capsule && !(p.length > 0))
    r.fail_table("length", p.grasper ? "a grasper needs length > 0 (m): its jaws' axis segment"
                                     : "a capsule needs length > 0 (m): its axis segment");
  if (!p.capsule && r.find("length"))
    r.fail_at(*r.find("length"), "length", "only a capsule has a length (shape = \"capsule\")");
  if (const toml::node* node = r.find("orientation")) {
    const toml::array* a = node->as_array();
    if (!a || a->size() != 4) r.fail_at(*node, "orientation", "expected a unit quaternion [w, x, y, z]");
    double norm = 0;
    for (std::size_t c = 0; c < 4; ++c) norm += std::pow(p.orientation[c] = r.as_number(*a->get(c), "orientation"), 2);
    if (!(std::abs(std::sqrt(norm) - 1) < 1e-6))
      r.fail_at(*node, "orientation", fmt::format("the quaternion's norm is {:.6g}, not 1", std::sqrt(norm)));
  }
  p.friction = r.number(
      "friction", p.friction, [](double m) { return m >= 0 && m <= 10; }, "must be in [0, 10]");
  p.non_negative_surface_map = r.choice("surface_map", "exact", {"exact", "non_negative"}) == "non_negative";
  p.sample_spacing = r.number("sample_spacing", p.sample_spacing, positive_up_to(1),
                              "must lie in (0, 1] (m: the contact's samples along the surface's edges)");
}

// a grasper driven by a device: its jaws' gap with the button up and held, and the time between (ProbeParams)
void read_device_grasper(TableReader& r, ProbeSpec& p) {
  if (!p.grasper) {
    for (const char* key : {"opening", "grip", "grip_time"})
      if (const toml::node* node = r.find(key)) r.fail_at(*node, key, "only a grasper has it (shape = \"grasper\")");
    return;
  }
  if (const toml::node* node = r.find("mode"))
    r.fail_at(*node, "mode", "a grasper has no mode: the device's button closes its jaws");
  if (const toml::node* node = r.find("position"))
    r.fail_at(*node, "position",
              "a grasper held by the scene is a [[tool]] without a device (position and opening, or keyframes = "
              "[[t, x, y, z, opening], ...])");
  for (const char* key : {"opening", "grip"})
    if (!r.find(key))
      r.fail_table(key,
                   "a grasper driven by a device needs opening = <m> (its jaws' gap, the button up) and grip = <m> "
                   "(the gap it closes to while the button is held)");
  p.opening = r.number("opening", 0.0, positive_up_to(1), "must lie in (0, 1] (m)");
  p.grip = r.number(
      "grip", 0.0, [&](double g) { return g >= 0 && g < p.opening; },
      "must lie in [0, opening) (m): the jaws' gap while the button is held");
  p.grip_time = r.number("grip_time", p.grip_time, positive_up_to(10), "must lie in (0, 10] (s)");
}

void read_probe(TableReader& r, ProbeSpec& p, const Context& ctx) {
  p.present = true;
  p.line = r.line();
  read_tool_shape(r, p);
  read_device_grasper(r, p);
  const std::string mode = r.choice("mode", "push", {"push", "grab", "cut"});
  p.grab = mode == "grab";
  p.cut = mode == "cut";
  p.cut_resistance =
      r.number("cut_resistance", p.cut_resistance, non_negative_up_to(1e9), "must lie in [0, 1e9] (J/m^2)");
  if (!p.cut && r.find("cut_resistance"))
    r.fail_at(*r.find("cut_resistance"), "cut_resistance", "only a blade cuts (mode = \"cut\")");
  if (r.find("trajectory") && r.find("keyframes"))
    r.fail_at(*r.find("keyframes"), "keyframes", "give either trajectory (a CSV file) or keyframes, not both");
  if (r.find("trajectory")) p.trajectory = resolve(ctx, r.string("trajectory", ""));
  if (const toml::node* node = r.find("keyframes")) {
    const toml::array* rows = node->as_array();
    if (!rows || rows->empty())
      r.fail_at(*node, "keyframes", "expected [[t, x, y, z], ...] (a 5th value 1 holds the button)");
    for (const toml::node& row : *rows) {
      const toml::array* a = row.as_array();
      if (!a || (a->size() != 4 && a->size() != 5))
        r.fail_at(row, "keyframes", "each keyframe is [t, x, y, z] or [t, x, y, z, button]");
      std::array<double, 5> k{0, 0, 0, 0, 0};
      for (std::size_t c = 0; c < a->size(); ++c) k[c] = r.as_number(*a->get(c), "keyframes");
      if (!p.keyframes.empty() && !(k[0] > p.keyframes.back()[0])) r.fail_at(row, "keyframes", "times must increase");
      p.keyframes.push_back(k);
    }
  }
  if (r.find("origin")) p.origin = r.vec3("origin", p.origin);
  p.scale = r.number("scale", p.scale, positive_up_to(1e6), "must lie in (0, 1e6] (scene metres per device metre)");
  p.stiffness = r.number("stiffness", p.stiffness, non_negative_up_to(1e9), "must lie in [0, 1e9] (N/m)");
  if (p.cut && !p.capsule)
    r.fail_table("shape",
                 "a blade (mode = \"cut\") is a capsule whose axis is its edge: give shape = \"capsule\" and length");
  p.object_stiffness = r.choice("local_stiffness", "contact", {"contact", "object"}) == "object";
  if (r.find("position")) {
    p.position = r.vec3("position", p.position);
    if (r.find("trajectory") || r.find("keyframes"))
      r.fail_at(*r.find("position"), "position",
                "a tool held at a position has no trajectory or keyframes: give one or the other");
  }
  read_press_direction(r, p);
}

void read_device(TableReader& r, DeviceSpec& d, const Context& ctx) {
  d.kind = r.choice("kind", "virtual", {"virtual", "replay", "openhaptics", "haply"});
  if (d.kind == "openhaptics") {
    d.library = r.string("library", d.library);
    d.hd_device = r.string("hd_device", d.hd_device);
  }
  if (d.kind == "haply") {
    d.host = r.string("host", d.host);
    d.port = static_cast<int>(r.number(
        "port", d.port, [](double x) { return x >= 1 && x <= 65535 && x == std::floor(x); },
        "must be a whole number in [1, 65535]"));
    d.device_id = r.string("device_id", d.device_id);
  }
  d.specs = r.choice("specs", "touch", {"touch", "omni", "falcon", "custom"});
  d.passivity_control = r.boolean("passivity_control", d.passivity_control);
  if (d.specs == "custom") {
    for (const char* key : {"max_force", "max_stiffness", "workspace_radius"})
      if (!r.find(key)) r.fail_table(key, "custom specs need max_force, max_stiffness and workspace_radius");
    // bounds well beyond any haptic device: specs of 1e300 were accepted and rendered 0 N all session
    d.max_force = r.number(
        "max_force", 0.0, [](double x) { return x > 0 && x <= 1e3; }, "must lie in (0, 1000] (N)");
    d.max_stiffness = r.number(
        "max_stiffness", 0.0, [](double x) { return x > 0 && x <= 1e6; }, "must lie in (0, 1e6] (N/m)");
    d.max_damping = r.number(
        "max_damping", 0.0, [](double x) { return x >= 0 && x <= 1e4; }, "must lie in [0, 1e4] (N s/m)");
    d.workspace_radius = r.number(
        "workspace_radius", 0.0, [](double x) { return x > 0 && x <= 10; }, "must lie in (0, 10] (m)");
    d.max_torque = r.number(
        "max_torque", 0.0, [](double x) { return x >= 0 && x <= 100; }, "must lie in [0, 100] (N m)");
  }
  if (d.kind == "replay") {
    if (!r.find("log")) r.fail_table("log", "a replay device needs log = \"session.csv\" (a recorded force log)");
    d.log = resolve(ctx, r.string("log", ""));
  }
}

// [[tool]]: name; driven by device = "NAME" (then every [probe] key), or posed: the shape's keys and position =
// [x, y, z] or keyframes = [[t, x, y, z], ...] (scene axes)
ToolSpec read_tool(TableReader& r, const Context& ctx) {
  ToolSpec t;
  t.line = r.line();
  t.name = r.string("name", "");
  if (t.name.empty()) r.fail_table("name", "a [[tool]] needs a name = \"...\" (its forces are reported by it)");
  t.device = r.string("device", "");
  if (!t.device.empty()) {
    read_probe(r, t.probe, ctx);
    return t;
  }
  t.probe.present = true;
  t.probe.line = t.line;
  read_tool_shape(r, t.probe);
  for (const char* key : {"mode", "trajectory", "origin", "scale", "stiffness", "local_stiffness", "cut_resistance"})
    if (const toml::node* node = r.find(key))
      r.fail_at(*node, key,
                "only a tool driven by a device has it (give device = \"NAME\" naming a [[device]]); a posed tool "
                "pushes, held at position = [x, y, z] or moved along keyframes = [[t, x, y, z], ...]");
  if ((r.find("position") != nullptr) == (r.find("keyframes") != nullptr))
    r.fail_table("position",
                 "a tool not driven by a device is held at position = [x, y, z] or moved along keyframes = [[t, x, "
                 "y, z], ...] (scene axes, m): give one of them, or device = \"NAME\"");
  if (r.find("position")) t.probe.position = r.vec3("position", t.probe.position);
  read_press_direction(r, t.probe);
  if (t.probe.grasper) {
    // its jaws' gap: at its position, or the 5th value of each keyframe
    if (r.find("position")) {
      if (!r.find("opening"))
        r.fail_table("opening", "a grasper held at a position needs opening = <m> (its jaws' gap)");
      t.opening.push_back(r.number("opening", 0.0, non_negative_up_to(1), "must lie in [0, 1] (m)"));
    } else if (const toml::node* node = r.find("opening")) {
      r.fail_at(*node, "opening", "a keyframed grasper's opening is each keyframe's 5th value: [t, x, y, z, opening]");
    }
    t.path = read_posed_keyframes(r, "[t, x, y, z, opening]", "a position", &t.opening);
  } else {
    if (const toml::node* node = r.find("opening"))
      r.fail_at(*node, "opening", "only a grasper has an opening (shape = \"grasper\")");
    t.path = read_posed_keyframes(r, "[t, x, y, z]", "a position");
  }
  return t;
}

DeviceTable read_device_table(TableReader& r, const Context& ctx) {
  DeviceTable d;
  d.line = r.line();
  d.name = r.string("name", "");
  if (d.name.empty()) r.fail_table("name", "a [[device]] needs a name = \"...\" (a [[tool]] names it)");
  read_device(r, d.spec, ctx);
  return d;
}

void read_lod(TableReader& r, LodSpec& l) {
  l.present = true;
  l.line = r.line();
  LodParams& p = l.params;
  p.k1 = r.number("k1", p.k1, non_negative_up_to(1e3), "must lie in [0, 1e3] (units of h)");
  p.k2 = r.number(
      "k2", p.k2, [&](double x) { return x >= p.k1 && x <= 1e3; }, "must lie in [k1, 1e3] (units of h)");
  if (const toml::node* node = r.find("levels")) {
    const toml::array* rows = node->as_array();
    if (!rows) r.fail_at(*node, "levels", "expected [ { distance = <h>, K = <0..10> }, ... ]");
    double previous = p.k2;
    int previous_k = 0;
    for (const toml::node& row : *rows) {
      const toml::table* t = row.as_table();
      if (!t) r.fail_at(row, "levels", "each level is { distance = <units of h>, K = <integer 0..10> }");
      TableReader level(r.context(), *t, r.name("levels"));
      if (!t->get("distance") || !t->get("K")) level.fail_table("distance", "each level needs both distance and K");
      LodLevel lv;
      lv.distance = level.number(
          "distance", 0.0, [&](double x) { return x > previous && x <= 1e3; },
          fmt::format("must exceed {} (k2 or the previous level's distance) and be at most 1e3", previous));
      const long long k = level.integer("K", 0);
      if (k < 0 || k > 10 || k < previous_k)
        level.fail_at(*t->get("K"), "K",
                      fmt::format("{} must be an integer in [{}, 10] (non-decreasing)", k, previous_k));
      lv.K = static_cast<int>(k);
      level.finish();
      previous = lv.distance;
      previous_k = lv.K;
      p.levels.push_back(lv);
    }
  }
  const toml::node* seed = r.find("seed");
  const long long seed_value = r.integer("seed", 1);
  if (seed_value < 0) r.fail_at(*seed, "seed", "must be >= 0");
  p.seed = static_cast<std::uint64_t>(seed_value);
  p.scheme = r.enumeration("scheme", p.scheme);
  p.reselect = r.number("reselect", p.reselect, positive_up_to(1e3), "must lie in (0, 1e3] (units of h)");
  p.reselect_interval = r.number(
      "reselect_interval", p.reselect_interval, [](double x) { return x >= 0 && x <= 1e3; },
      "must lie in [0, 1000] (s)");
  const toml::node* mn = r.find("min_neighbours");
  const long long min_neighbours = r.integer("min_neighbours", p.min_neighbours);
  if (min_neighbours < 1 || min_neighbours > 1000) r.fail_at(*mn, "min_neighbours", "must lie in [1, 1000]");
  p.min_neighbours = static_cast<int>(min_neighbours);
  p.max_widening = r.number(
      "max_widening", p.max_widening, [](double x) { return x >= 1 && x <= 10; }, "must lie in [1, 10]");
  if (r.find("contact")) l.contact = r.vec3("contact", l.contact);
}

// [[tool]] and [[device]] tables: unique names; each device drives one tool and each tool's device exists. A tool
// driven by a device becomes the scene's probe and its device (one hand: a second is refused by name); the posed
// ones stay in scene.tools.
void bind_tools(Scene& scene, bool device_section) {
  const auto fail = [&](int line, const std::string& what) {
    throw Error(fmt::format("{}:{}: {}", scene.path, line, what));
  };
  for (std::size_t a = 0; a < scene.tools.size(); ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (scene.tools[a].name == scene.tools[b].name)
        fail(scene.tools[a].line,
             fmt::format("tool[{}].name: \"{}\" is already the name of tool[{}] (names are unique)", a,
                         scene.tools[a].name, b));
  for (std::size_t a = 0; a < scene.devices.size(); ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (scene.devices[a].name == scene.devices[b].name)
        fail(scene.devices[a].line,
             fmt::format("device[{}].name: \"{}\" is already the name of device[{}] (names are unique)", a,
                         scene.devices[a].name, b));
  std::vector<int> driven(scene.devices.size(), -1);       // the tool each device drives
  std::vector<std::pair<std::size_t, std::size_t>> hands;  // the device-driven tools and their devices
  for (std::size_t k = 0; k < scene.tools.size(); ++k) {
    const ToolSpec& t = scene.tools[k];
    if (t.device.empty()) continue;
    const auto d = std::find_if(scene.devices.begin(), scene.devices.end(),
                                [&](const DeviceTable& d) { return d.name == t.device; });
    if (d == scene.devices.end()) {
      std::string names;
      for (const DeviceTable& e : scene.devices) names += (names.empty() ? "\"" : ", \"") + e.name + "\"";
      fail(t.line, fmt::format("tool[{}].device: no [[device]] is named \"{}\"{}", k, t.device,
                               names.empty() ? std::string(" (the scene has no [[device]] table)")
                                             : fmt::format(" (the devices: {})", names)));
    }
    const auto slot = static_cast<std::size_t>(d - scene.devices.begin());
    if (driven[slot] >= 0)
      fail(t.line, fmt::format("tool[{}].device: \"{}\" already drives tool[{}] \"{}\" (one tool per device)", k,
                               t.device, driven[slot], scene.tools[static_cast<std::size_t>(driven[slot])].name));
    driven[slot] = static_cast<int>(k);
    hands.emplace_back(k, slot);
    if (t.probe.held())
      fail(t.line, fmt::format("tool[{}].position: a tool driven by a device is not held at a position (leave out "
                               "position, or device)",
                               k));
    if (scene.probe.present || device_section)
      fail(t.line, fmt::format("tool[{}].device: the scene's [probe] / [device] already make its device-driven tool "
                               "(give it either as [probe] and [device] or as [[tool]] and [[device]])",
                               k));
  }
  for (std::size_t k = 0; k < scene.devices.size(); ++k)
    if (driven[k] < 0)
      fail(scene.devices[k].line,
           fmt::format("device[{}]: \"{}\" drives no tool (a [[tool]] names it: device = \"{}\")", k,
                       scene.devices[k].name, scene.devices[k].name));
  // the first device-driven tool is the scene's probe, its device the scene's device; the others are more hands
  if (hands.empty()) return;
  for (std::size_t h = 0; h < hands.size(); ++h) {
    const auto [tool, device] = hands[h];
    if (h == 0) {
      scene.probe = scene.tools[tool].probe;
      scene.device = scene.devices[device].spec;
      scene.probe_name = scene.tools[tool].name;
    } else {
      scene.other_hands.push_back({scene.tools[tool].name, scene.tools[tool].probe, scene.devices[device].spec});
    }
  }
  std::erase_if(scene.tools, [](const ToolSpec& t) { return !t.device.empty(); });
}

// Each [[fixed]] and [[load]] names an [[object]] (optional with one, and for gravity, which loads every one), and
// what does not yet work with several objects is refused by name
void check_body_names(const Scene& scene) {
  const auto known = [&](const std::string& object) {
    return std::any_of(scene.bodies.begin(), scene.bodies.end(), [&](const BodySpec& b) { return b.name == object; });
  };
  const auto check = [&](const std::string& object, std::string_view key, std::size_t k, int line, bool optional) {
    const std::string where = fmt::format("{}:{}: {}[{}].object", scene.path, line, key, k);
    if (object.empty()) {
      if (scene.bodies.size() > 1 && !optional)
        throw Error(
            fmt::format("{}: missing: with several [[object]] tables, name the one it applies to "
                        "(object = \"NAME\")",
                        where));
      return;
    }
    if (scene.bodies.empty())
      throw Error(
          fmt::format("{}: \"{}\" names an [[object]], but the scene has one [object] (leave it out)", where, object));
    if (!known(object)) {
      std::string names;
      for (const BodySpec& b : scene.bodies) names += (names.empty() ? "\"" : ", \"") + b.name + "\"";
      throw Error(fmt::format("{}: no [[object]] is named \"{}\" (the objects: {})", where, object, names));
    }
  };
  for (std::size_t k = 0; k < scene.fixed.size(); ++k)
    check(scene.fixed[k].object, "fixed", k, scene.fixed[k].line, false);
  for (std::size_t k = 0; k < scene.loads.size(); ++k)
    check(scene.loads[k].object, "load", k, scene.loads[k].line, scene.loads[k].kind == LoadKind::GRAVITY);
  for (std::size_t k = 0; k < scene.cuts.size(); ++k) check(scene.cuts[k].object, "cut", k, scene.cuts[k].line, false);
  for (std::size_t k = 0; k < scene.regions.size(); ++k)
    check(scene.regions[k].object, "region", k, scene.regions[k].line, false);
  for (std::size_t k = 0; k < scene.refine.size(); ++k)
    check(scene.refine[k].object, "refine", k, scene.refine[k].line, false);
  for (std::size_t k = 0; k < scene.contact.pairs.size(); ++k)
    for (const std::string& name : scene.contact.pairs[k].bodies)
      if (!known(name))
        throw Error(fmt::format("{}:{}: contact.pairs[{}].bodies: no [[object]] is named \"{}\"", scene.path,
                                scene.contact.line, k, name));
  if (scene.bodies.size() < 2) {
    if (scene.contact.line > 0)
      throw Error(
          fmt::format("{}:{}: contact: [contact] is between several [[object]] tables (this scene has one "
                      "object; a tool's friction is [probe] friction, an obstacle's its own)",
                      scene.path, scene.contact.line));
    return;
  }
  // not yet: an active set is one object's points
  if (scene.lod.present)
    throw Error(fmt::format("{}:{}: lod: not yet with several [[object]] tables (an active set is one object's)",
                            scene.path, scene.lod.line));
}

// [[name]] arrays of tables
template <class Read>
void read_array_of_tables(TableReader& root, std::string_view key, Read read) {
  const toml::node* node = root.find(key);
  if (!node) return;
  const toml::array* array = node->as_array();
  if (!array || !array->is_array_of_tables())
    root.fail_at(*node, key, fmt::format("expected one or more [[{}]] tables", key));
  int k = 0;
  for (const toml::node& item : *array) {
    TableReader r(root.context(), *item.as_table(), fmt::format("{}[{}]", key, k++));
    read(r);
    r.finish();
  }
}

}  // namespace

SceneSetting parse_scene_setting(std::string_view text) {
  const std::size_t equals = text.find('=');
  if (equals == std::string_view::npos || equals == 0)
    throw Error(fmt::format("--set {}: expected key=value (e.g. material.young=2e5)", text));
  return {std::string(text.substr(0, equals)), std::string(text.substr(equals + 1))};
}

Scene parse_scene(std::string_view text, const std::string& name, const std::string& base_dir,
                  const std::vector<SceneSetting>& settings) {
  Context ctx{name, base_dir, &settings};
  toml::table root;
  check_key_nesting(text, name);
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    throw Error(fmt::format("{}:{}: TOML syntax error: {}", name, e.source().begin.line, e.description()));
  }
  for (const SceneSetting& s : settings) apply_setting(root, s, name);
  Scene scene;
  scene.path = name;
  TableReader top(ctx, root, "");
  auto section = [&](std::string_view key, auto read) {
    if (const toml::table* t = top.subtable(key)) {
      TableReader r(ctx, *t, std::string(key));
      read(r);
      r.finish();
    }
  };
  const toml::node* objects = root.get("object");
  if (!objects) throw Error(fmt::format("{}:1: object: missing [object] section", name));
  section("material", [&](TableReader& r) { read_material(r, scene.material); });  // [[object]]s start from it
  if (objects->is_array_of_tables()) {
    read_array_of_tables(top, "object",
                         [&](TableReader& r) { scene.bodies.push_back(read_body(r, scene.material, ctx)); });
    for (std::size_t a = 0; a < scene.bodies.size(); ++a)
      for (std::size_t b = 0; b < a; ++b)
        if (scene.bodies[a].name == scene.bodies[b].name)
          throw Error(fmt::format("{}:{}: object[{}].name: \"{}\" is already the name of object[{}] (names are unique)",
                                  name, scene.bodies[a].object.line, a, scene.bodies[a].name, b));
    scene.object = scene.bodies.front().object;
    scene.material = scene.bodies.front().material;
  } else {
    section("object", [&](TableReader& r) { read_object(r, scene.object, ctx); });
  }
  section("kernel", [&](TableReader& r) { read_kernel(r, scene.kernel); });
  section("solver", [&](TableReader& r) { read_solver(r, scene.solver); });
  section("probe", [&](TableReader& r) { read_probe(r, scene.probe, ctx); });
  const toml::node* device_node = root.get("device");
  if (device_node && device_node->is_array_of_tables())
    read_array_of_tables(top, "device", [&](TableReader& r) { scene.devices.push_back(read_device_table(r, ctx)); });
  else section("device", [&](TableReader& r) { read_device(r, scene.device, ctx); });
  read_array_of_tables(top, "tool", [&](TableReader& r) { scene.tools.push_back(read_tool(r, ctx)); });
  const bool device_section = device_node && !device_node->is_array_of_tables();
  bind_tools(scene, device_section);
  section("lod", [&](TableReader& r) { read_lod(r, scene.lod); });
  section("contact", [&](TableReader& r) { read_contact(r, scene.contact); });
  if (const toml::node* reduction = root.get("reduction")) {
    scene.solver.reduction.line = static_cast<int>(reduction->source().begin.line);
    section("reduction", [&](TableReader& r) { read_reduction(r, ctx, scene.solver.reduction); });
  }
  // each device-driven tool (a hand): [probe], or a [[tool]] with a device
  const auto check_hand = [&](const ProbeSpec& probe, const DeviceSpec& device, const std::string& what) {
    if (device.kind == "virtual" && probe.trajectory.empty() && probe.keyframes.empty())
      throw Error(
          fmt::format("{}:{}: {}: a virtual device needs trajectory = \"probe.csv\" or keyframes = [[t, x, y, z], ...] "
                      "(or position = [x, y, z] for a tool held there)",
                      name, probe.line, what));
    if (probe.friction > 0 && scene.lod.present)
      throw Error(
          fmt::format("{}:{}: {}.friction: a device's probe with levels of detail touches the point spheres, which "
                      "are frictionless",
                      name, probe.line, what));
    if (scene.solver.kind == SolverKind::STATIC)
      throw Error(
          fmt::format("{}:{}: {}: a static solve holds the tool at a position: give position = [x, y, z] (a probe "
                      "driven by a device needs solver.kind = \"explicit\" or \"implicit\")",
                      name, probe.line, what));
  };
  if (scene.probe.present && !scene.probe.held())
    check_hand(scene.probe, scene.device, scene.probe_name.empty() ? "probe" : "tool \"" + scene.probe_name + "\"");
  for (const SceneHand& hand : scene.other_hands) {
    check_hand(hand.probe, hand.device, "tool \"" + hand.name + "\"");
    if (scene.lod.present)
      throw Error(
          fmt::format("{}:{}: tool \"{}\": a second device-driven tool (two hands) is not yet with levels "
                      "of detail (the active set follows one contact)",
                      name, hand.probe.line, hand.name));
  }
  if (scene.probe.held() && device_section)
    throw Error(
        fmt::format("{}:{}: probe: a tool held at a position is not driven by a [device]", name, scene.probe.line));
  if (device_section && !scene.probe.present)
    throw Error(fmt::format("{}: device: a [device] needs a [probe] to drive", name));
  read_array_of_tables(top, "fixed", [&](TableReader& r) { scene.fixed.push_back(read_fixed(r)); });
  read_array_of_tables(top, "region", [&](TableReader& r) { scene.regions.push_back(read_region(r)); });
  read_array_of_tables(top, "load", [&](TableReader& r) { scene.loads.push_back(read_load(r)); });
  read_array_of_tables(top, "cut", [&](TableReader& r) { scene.cuts.push_back(read_cut(r)); });
  read_array_of_tables(top, "obstacle", [&](TableReader& r) { scene.obstacles.push_back(read_obstacle(r)); });
  for (std::size_t a = 0; a < scene.obstacles.size(); ++a)
    for (std::size_t b = 0; b < a; ++b)
      if (scene.obstacles[a].name == scene.obstacles[b].name)
        throw Error(
            fmt::format("{}:{}: obstacle[{}].name: \"{}\" is already the name of obstacle[{}] (names are "
                        "unique)",
                        name, scene.obstacles[a].line, a, scene.obstacles[a].name, b));
  if (!scene.tools.empty() && scene.lod.present)
    throw Error(fmt::format("{}:{}: tool: a [[tool]] not yet with levels of detail (use [probe])", name,
                            scene.tools.front().line));
  if (!scene.obstacles.empty() && scene.lod.present)
    throw Error(
        fmt::format("{}:{}: obstacle: not yet with levels of detail (an active set carries only part of the "
                    "surface)",
                    name, scene.obstacles.front().line));
  if (scene.probe.cut && scene.probe.held())
    throw Error(fmt::format("{}:{}: probe.mode: a blade cuts as the device moves it, not held at a position", name,
                            scene.probe.line));
  read_array_of_tables(top, "refine", [&](TableReader& r) { scene.refine.push_back(read_refine(r, scene)); });
  if (!scene.refine.empty() && scene.lod.present)
    throw Error(fmt::format("{}:{}: refine: not yet with levels of detail ([lod] thins a uniform sampling)", name,
                            scene.refine.front().line));
  top.finish();
  check_body_names(scene);
  if (scene.solver.reduction.modes > 0) {
    // what a reduced model does not do yet (issue 49): each named, at the [reduction] table
    const std::pair<bool, const char*> not_yet[] = {
        {scene.solver.kind == SolverKind::EXPLICIT, "needs solver.kind = \"implicit\" or \"static\""},
        {scene.probe.held() || scene.probe.cut || scene.probe.grasper || scene.probe.grab || !scene.tools.empty(),
         "a device's probe pushing (mode = \"push\") is coupled to a reduced model; a held probe (position), a "
         "blade, a grasper, grabbing and [[tool]] tables are not yet"},
        {!scene.obstacles.empty(), "not yet with [[obstacle]] tables"},
        {scene.bodies.size() > 1, "not yet with several [[object]] tables"},
        {scene.lod.present, "not yet with [lod]"},
        {!scene.cuts.empty(), "not yet with [[cut]] tables (a cut invalidates the basis)"},
        {scene.material.model != MaterialModel::SVK,
         "forces = \"polynomial\" needs material.model = \"svk\" (St. Venant-Kirchhoff's energy is a polynomial)"},
    };
    for (const auto& [refused, why] : not_yet)
      if (refused) throw Error(fmt::format("{}:{}: reduction: {}", name, scene.solver.reduction.line, why));
  }
  if (scene.lod.present && !scene.probe.present && !scene.lod.contact.allFinite()) {
    int point_loads = 0;
    for (const LoadSpec& l : scene.loads) point_loads += l.kind == LoadKind::POINT;
    if (point_loads != 1)
      throw Error(
          fmt::format("{}:{}: lod.contact: missing; without a [probe] or exactly one point load, give the "
                      "contact point as contact = [x, y, z] (m)",
                      name, scene.lod.line));
  }
  return scene;
}

Scene read_scene_file(const std::string& path, const std::vector<SceneSetting>& settings) {
  check_input_file(path, "scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open the scene file", path));
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return parse_scene(buffer.str(), path, dir.empty() ? "." : dir, settings);
}

}  // namespace pointhaptics
