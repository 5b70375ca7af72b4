#include <pointhaptics/bodies/join_models.hpp>

#include <pointhaptics/core/error.hpp>

#include <fmt/format.h>

#include <algorithm>

namespace pointhaptics {

namespace {

// columns of each body's matrix side by side
template <class Matrix, class Part>
Matrix side_by_side(const std::vector<Model>& bodies, Part part, Eigen::Index rows) {
  Eigen::Index cols = 0;
  for (const Model& b : bodies) cols += part(b).cols();
  Matrix out(rows, cols);
  Eigen::Index at = 0;
  for (const Model& b : bodies) {
    out.middleCols(at, part(b).cols()) = part(b);
    at += part(b).cols();
  }
  return out;
}

Eigen::VectorXd stacked(const std::vector<Model>& bodies, const auto& part) {
  Eigen::Index n = 0;
  for (const Model& b : bodies) n += b.n_points;
  Eigen::VectorXd out(n);
  Eigen::Index at = 0;
  for (const Model& b : bodies) {
    out.segment(at, b.n_points) = part(b);
    at += b.n_points;
  }
  return out;
}

}  // namespace

Model join_models(std::vector<Model> bodies, std::vector<std::string> names) {
  if (bodies.empty() || bodies.size() != names.size()) throw Error("join_models: one name per body, at least one");
  for (std::size_t k = 0; k < bodies.size(); ++k)
    if (bodies[k].n_passive > 0 || !bodies[k].body_start.empty())
      throw Error(
          fmt::format("object \"{}\": a body joined to others has no passive points and is one body", names[k]));
  Model m;
  m.kernel = bodies.front().kernel;
  m.material = bodies.front().material;
  m.lambda = bodies.front().lambda;
  m.mu = bodies.front().mu;
  m.body_names = std::move(names);
  m.body_start.push_back(0);
  for (const Model& b : bodies) m.body_start.push_back(m.body_start.back() + b.n_points);
  m.n_points = m.body_start.back();

  m.X = side_by_side<Points>(
      bodies, [](const Model& b) -> const Points& { return b.X; }, 3);
  m.f_ext = side_by_side<Points>(
      bodies, [](const Model& b) -> const Points& { return b.f_ext; }, 3);
  m.d_self = side_by_side<Points>(
      bodies, [](const Model& b) -> const Points& { return b.d_self; }, 3);
  m.d = side_by_side<Points>(
      bodies, [](const Model& b) -> const Points& { return b.d; }, 3);
  m.volume = stacked(bodies, [](const Model& b) { return b.volume; });
  m.mass = stacked(bodies, [](const Model& b) { return b.mass; });
  m.stiffness_volume = stacked(bodies, [](const Model& b) { return b.stiffness_volume; });
  m.hg_diagonal = stacked(bodies, [](const Model& b) { return b.hg_diagonal; });

  m.h = 0;
  m.spacing = bodies.front().spacing;
  bool same_support = true, scaled = false;
  for (const Model& b : bodies) {
    m.h = std::max(m.h, b.h);
    m.spacing = std::min(m.spacing, b.spacing);
    same_support = same_support && b.support.size() == 0 && b.h == bodies.front().h;
    scaled = scaled || b.stiffness_scale.size() > 0;
  }
  if (!same_support)
    m.support = stacked(bodies, [](const Model& b) -> Eigen::VectorXd {
      return b.support.size() ? b.support : Eigen::VectorXd::Constant(b.n_points, b.h);
    });
  if (scaled)
    m.stiffness_scale = stacked(bodies, [](const Model& b) -> Eigen::VectorXd {
      return b.stiffness_scale.size() ? b.stiffness_scale : Eigen::VectorXd::Ones(b.n_points);
    });

  // each body's materials after the first body's own, which is the joined model's `material`
  m.point_materials.push_back(m.material);
  m.material_of.reserve(static_cast<std::size_t>(m.n_points));
  for (const Model& b : bodies) {
    const std::size_t first = m.point_materials.size();
    if (b.point_materials.empty()) m.point_materials.push_back(b.material);
    else m.point_materials.insert(m.point_materials.end(), b.point_materials.begin(), b.point_materials.end());
    if (m.point_materials.size() > 256)
      throw Error(fmt::format("objects: {} materials in all, at most 256", m.point_materials.size()));
    for (index_t i = 0; i < b.n_points; ++i)
      m.material_of.push_back(static_cast<std::uint8_t>(first + (b.material_of.empty() ? 0 : b.material_of[i])));
  }

  // the neighbour lists, each body's pairs after the previous bodies'
  m.neighbours.offset.assign(1, 0);
  index_t pairs = 0;
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    const Model& b = bodies[k];
    const index_t first_point = m.body_start[k];
    for (index_t i = 0; i < b.n_points; ++i) m.neighbours.offset.push_back(pairs + b.neighbours.offset[i + 1]);
    for (index_t j : b.neighbours.index) m.neighbours.index.push_back(first_point + j);
    for (index_t e : b.reverse_pair) m.reverse_pair.push_back(pairs + e);
    m.hg_coef.conservativeResize(pairs + b.n_pairs());
    m.hg_coef.tail(b.n_pairs()) = b.hg_coef;
    pairs += b.n_pairs();
  }

  // held points, their groups and the diagnostics
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    Model& b = bodies[k];
    m.fixed.insert(m.fixed.end(), b.fixed.begin(), b.fixed.end());
    for (FixedGroup& g : b.fixed_groups) {
      for (index_t& i : g.points) i += m.body_start[k];
      m.fixed_groups.push_back(std::move(g));
    }
    ModelDiagnostics& d = m.diagnostics;
    const ModelDiagnostics& e = b.diagnostics;
    d.regularised_neighbourhoods += e.regularised_neighbourhoods;
    d.isolated_points += e.isolated_points;
    d.min_neighbours = k == 0 ? e.min_neighbours : std::min(d.min_neighbours, e.min_neighbours);
    d.mean_neighbours += e.mean_neighbours * static_cast<double>(b.n_points) / static_cast<double>(m.n_points);
    d.worst_condition = std::max(d.worst_condition, e.worst_condition);
    d.severed_pairs += e.severed_pairs;
  }
  const Vec3 lo = m.X.rowwise().minCoeff(), hi = m.X.rowwise().maxCoeff();
  m.extent = (hi - lo).norm() + m.h;
  return m;
}

}  // namespace pointhaptics
