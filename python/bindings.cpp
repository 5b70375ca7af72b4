// Python bindings (pybind11): load a scene or build a model from NumPy arrays, step, read positions,
// displacements, forces and energy as NumPy arrays (views without copies where the data lives in the
// simulation), drive the probe. Long calls release the GIL.
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/io/point_cloud_file.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/pointhaptics.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <mutex>

namespace py = pybind11;
namespace ph = pointhaptics;

namespace {

using RowPoints = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A read-only (n, 3) view of a 3 x n column-major Points buffer owned by `owner`.
py::array view(const ph::Points& P, py::handle owner) {
  py::array a(py::dtype::of<double>(), {P.cols(), Eigen::Index{3}}, {Eigen::Index{3 * sizeof(double)}, Eigen::Index{sizeof(double)}},
              P.data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

// (n, 3) array -> Points (3 x n), with a named error for a wrong shape or non-finite values
ph::Points points_of(const RowPoints& a, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw ph::Error(std::string(what) + ": expected an (n, 3) array");
  ph::Points P(3, a.shape(0));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    for (int c = 0; c < 3; ++c) P(c, i) = r(i, c);
  if (!P.allFinite()) throw ph::Error(std::string(what) + ": a value is not finite");
  return P;
}

py::dict summary_dict(const ph::RunSummary& s) {
  py::dict d;
  d["solver"] = s.solver_kind;
  d["converged"] = s.converged;
  d["steps"] = s.steps;
  d["iterations"] = s.iterations;
  d["residual"] = s.residual;
  d["strain_energy"] = s.strain_energy;
  d["kinetic_energy"] = s.kinetic_energy;
  d["steps_per_s"] = s.steps_per_s;
  d["stable_dt"] = s.stable_dt;
  if (s.solver_kind == "implicit") d["budget_steps"] = s.budget_steps;
  py::list reactions;
  for (const ph::Vec3& r : s.reactions) reactions.append(py::make_tuple(r.x(), r.y(), r.z()));
  d["reactions"] = reactions;
  if (s.lod.enabled) d["lod_selected"] = s.lod.selected;
  if (!s.failure.empty()) d["failure"] = s.failure;
  return d;
}

ph::SolverKind solver_kind(const std::string& kind) {
  if (kind == "static") return ph::SolverKind::STATIC;
  if (kind == "explicit") return ph::SolverKind::EXPLICIT;
  if (kind == "implicit") return ph::SolverKind::IMPLICIT;
  throw ph::Error("solver: unknown kind \"" + kind + "\" (expected static | explicit | implicit)");
}

ph::KernelType kernel_type(const std::string& type) {
  if (type == "poly6") return ph::KernelType::POLY6;
  if (type == "spiky") return ph::KernelType::SPIKY;
  if (type == "viscosity") return ph::KernelType::VISCOSITY;
  if (type == "quadratic") return ph::KernelType::QUADRATIC;
  throw ph::Error("kernel: unknown type \"" + type + "\" (expected poly6 | spiky | viscosity | quadratic)");
}

// The simulation with the scene it came from (for its probe), so that Python owns one object. Calls that
// release the GIL run concurrently with other Python threads, so every call on one object takes its mutex:
// a step and a read, or two steps, from two threads follow each other instead of sharing the state.
struct PySimulation {
  std::unique_ptr<ph::Simulation> sim;
  ph::Scene scene;
  std::mutex mutex;
};

// The object's lock for a call that holds the GIL: waiting for it (a step on another thread may hold it
// for long) releases the GIL, so that the holder, which never takes the GIL while holding the lock, can
// finish.
std::unique_lock<std::mutex> locked(PySimulation& p) {
  std::unique_lock<std::mutex> lock(p.mutex, std::try_to_lock);
  if (!lock.owns_lock()) {
    py::gil_scoped_release release;
    lock.lock();
  }
  return lock;
}

std::unique_ptr<PySimulation> from_scene(const std::string& path, int threads) {
  auto p = std::make_unique<PySimulation>();
  p->scene = ph::read_scene_file(path);
  p->sim = std::make_unique<ph::Simulation>(ph::build_scene_model(p->scene), p->scene.solver, threads);
  if (p->scene.lod.present) p->sim->enable_lod(p->scene.lod.params, ph::scene_lod_contact(p->scene, p->sim->model()));
  return p;
}

std::unique_ptr<PySimulation> from_points(const RowPoints& X, double spacing, py::object fixed, py::object forces,
                                          double young, double poisson, double density, double damping, const std::string& kernel,
                                          double support_factor, const std::string& solver, double dt, int threads) {
  // the same rules as scene files and the point-cloud readers (issue 21: these were accepted here)
  if (!(spacing > 0) || !std::isfinite(spacing)) throw ph::Error("spacing: must be > 0 (m)");
  if (!(dt >= 1e-9 && dt <= 1)) throw ph::Error("dt: must lie in [1e-9, 1] (s)");
  if (threads < 0) throw ph::Error("threads: must be >= 0 (0: all hardware threads)");
  if (!(support_factor > 1 && support_factor <= 20)) throw ph::Error("support_factor: must lie in (1, 20]");
  const ph::PointCloud cloud = ph::point_cloud_from_positions(points_of(X, "points"), "points", spacing);
  ph::MaterialParams material;
  material.young = young;
  material.poisson = poisson;
  material.density = density;
  material.damping = damping;
  if (!(young > 0) || !(poisson > -1 && poisson < 0.5) || !(density > 0) || !(damping >= 0))
    throw ph::Error("material: young > 0, -1 < poisson < 0.5, density > 0 and damping >= 0 are needed");
  ph::KernelParams k;
  k.type = kernel_type(kernel);
  k.support_factor = support_factor;
  auto p = std::make_unique<PySimulation>();
  p->scene.solver.kind = solver_kind(solver);
  p->scene.solver.dt = dt;
  ph::Model model = ph::build_model(cloud, material, k);
  if (!fixed.is_none()) {
    const auto mask = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(fixed);
    if (!mask || mask.ndim() != 1 || mask.shape(0) != model.n_points) throw ph::Error("fixed: expected a boolean array of n values");
    ph::FixedGroup group;
    group.name = "fixed";
    for (ph::index_t i = 0; i < model.n_points; ++i)
      if (mask.at(i)) {
        model.fixed[i] = 1;
        group.points.push_back(i);
      }
    if (!group.points.empty()) model.fixed_groups.push_back(group);
  }
  ph::check_every_free_point_has_neighbours(model, "points");
  if (!forces.is_none()) model.f_ext = points_of(RowPoints::ensure(forces), "forces");
  if (model.f_ext.cols() != model.n_points) throw ph::Error("forces: expected an (n, 3) array");
  p->sim = std::make_unique<ph::Simulation>(std::move(model), p->scene.solver, threads);
  return p;
}

}  // namespace

PYBIND11_MODULE(_pointhaptics, m) {
  m.doc() = "PointHaptics: meshless (MLS) deformable objects for haptic rendering";
  py::register_exception<ph::Error>(m, "Error", PyExc_ValueError);

  py::class_<PySimulation>(m, "Simulation")
      .def_static("from_scene", &from_scene, py::arg("path"), py::arg("threads") = 0,
                  "Load a scene file (design.md's TOML) and prepare its simulation, with its levels of detail")
      .def_static("from_points", &from_points, py::arg("points"), py::arg("spacing"), py::arg("fixed") = py::none(),
                  py::arg("forces") = py::none(), py::arg("young") = 1e5, py::arg("poisson") = 0.4, py::arg("density") = 1000.0,
                  py::arg("damping") = 0.0, py::arg("kernel") = "poly6", py::arg("support_factor") = 2.0,
                  py::arg("solver") = "explicit", py::arg("dt") = 1e-3, py::arg("threads") = 0,
                  "Build a model from an (n, 3) array of points (m) sampled at `spacing`, with an optional boolean "
                  "`fixed` mask and (n, 3) constant `forces` (N)")
      .def(
          "step", [](PySimulation& p) {
            py::gil_scoped_release release;
            const std::lock_guard<std::mutex> lock(p.mutex);
            p.sim->step();
          },
          "One solver step (static: the equilibrium)")
      .def(
          "run", [](PySimulation& p, double duration) {
            if (!(duration >= 0)) throw ph::Error("run: duration must be >= 0 (s)");
            py::gil_scoped_release release;
            const std::lock_guard<std::mutex> lock(p.mutex);
            p.sim->run(duration);
          },
          py::arg("duration"), "Step until `duration` seconds more have passed (static: solve once); releases the GIL")
      .def_property_readonly("time", [](PySimulation& p) {
        const auto lock = locked(p);
        return p.sim->full_state().time;
      })
      .def_property_readonly("n_points", [](PySimulation& p) { return p.sim->full_model().n_points; })
      .def_property_readonly(
          "reference", [](py::object self) { return view(self.cast<PySimulation&>().sim->full_model().X, self); },
          "Reference positions, an (n, 3) read-only view (m)")
      .def_property_readonly(
          "displacement",
          [](py::object self) {
            PySimulation& p = self.cast<PySimulation&>();
            const auto lock = locked(p);
            return view(p.sim->full_state().u, self);
          },
          "Displacements, an (n, 3) read-only view into the simulation (m): it changes as the simulation steps")
      .def_property_readonly(
          "velocity",
          [](py::object self) {
            PySimulation& p = self.cast<PySimulation&>();
            const auto lock = locked(p);
            return view(p.sim->full_state().velocity, self);
          },
          "Velocities, an (n, 3) read-only view (m/s)")
      .def_property_readonly(
          "positions",
          [](PySimulation& p) {
            const auto lock = locked(p);
            const ph::Points x = p.sim->full_model().X + p.sim->full_state().u;
            return py::array_t<double>({x.cols(), Eigen::Index{3}}, {Eigen::Index{3 * sizeof(double)}, Eigen::Index{sizeof(double)}},
                                       x.data());
          },
          "Current positions X + u, an (n, 3) array (a copy)")
      .def_property_readonly(
          "forces",
          [](PySimulation& p) {
            const auto lock = locked(p);
            const ph::Model& m = p.sim->model();
            ph::Workspace ws(m, 1);
            ph::compute_internal_forces(m, p.sim->state().u, ws);
            return py::array_t<double>({ws.f_int.cols(), Eigen::Index{3}},
                                       {Eigen::Index{3 * sizeof(double)}, Eigen::Index{sizeof(double)}}, ws.f_int.data());
          },
          "Internal elastic forces on the simulated points, an (n_simulated, 3) array (N)")
      .def_property_readonly("fixed",
                             [](PySimulation& p) {
                               const ph::Model& m = p.sim->full_model();
                               py::array_t<bool> a(m.n_points);
                               for (ph::index_t i = 0; i < m.n_points; ++i) a.mutable_at(i) = m.fixed[i] != 0;
                               return a;
                             })
      .def("energy",
           [](PySimulation& p) {
             const auto lock = locked(p);
             const ph::EnergyTerms e = ph::strain_energy(p.sim->model(), p.sim->state().u);
             py::dict d;
             d["strain"] = e.total();
             d["kinetic"] = ph::kinetic_energy(p.sim->model(), p.sim->state().velocity);
             return d;
           },
           "Strain and kinetic energy (J)")
      .def(
          "summary",
          [](PySimulation& p) {
            const auto lock = locked(p);
            return summary_dict(p.sim->summary());
          },
          "Solver outcome, energies, timing")
      .def(
          "probe",
          [](PySimulation& p, const std::vector<std::array<double, 5>>& keyframes, double radius, const std::string& mode,
             double duration, bool real_time) {
            if (keyframes.empty()) throw ph::Error("probe: keyframes [[t, x, y, z, button], ...] are needed");
            std::vector<ph::Keyframe> frames;
            for (const auto& k : keyframes) frames.push_back({k[0], ph::Vec3(k[1], k[2], k[3]), k[4] != 0});
            ph::VirtualDevice device(ph::Trajectory(std::move(frames)), ph::known_device_specs("touch"));
            ph::Scene scene = p.scene;
            scene.probe.present = true;
            scene.probe.radius = radius;
            if (mode != "push" && mode != "grab") throw ph::Error("probe: mode must be push or grab");
            scene.probe.grab = mode == "grab";
            scene.solver.duration = duration;
            ph::InteractiveOptions o = ph::scene_interactive_options(scene, p.sim->full_model());
            o.real_time = real_time;
            ph::InteractiveResult r;
            {
              py::gil_scoped_release release;
              const std::lock_guard<std::mutex> lock(p.mutex);
              r = ph::run_interactive(*p.sim, device, o);
            }
            py::array_t<double> log({static_cast<py::ssize_t>(r.log.size()), py::ssize_t{8}});
            auto w = log.mutable_unchecked<2>();
            for (std::size_t k = 0; k < r.log.size(); ++k) {
              const ph::HapticLogRow& row = r.log[k];
              const double v[8] = {row.t, row.position.x(), row.position.y(), row.position.z(), row.force.x(), row.force.y(),
                                   row.force.z(), static_cast<double>(row.buttons)};
              for (int c = 0; c < 8; ++c) w(static_cast<py::ssize_t>(k), c) = v[c];
            }
            py::dict d;
            d["log"] = log;
            d["ticks"] = r.haptic.ticks;
            d["max_force"] = r.haptic.max_force_n;
            d["max_contacts"] = r.max_contacts;
            d["simulation_steps"] = r.simulation_steps;
            return d;
          },
          py::arg("keyframes"), py::arg("radius") = 0.005, py::arg("mode") = "push", py::arg("duration") = 1.0,
          py::arg("real_time") = false,
          "Drive a spherical probe with a virtual hand through keyframes [t, x, y, z, button] (device frame, m; the origin "
          "two radii above the object's top centre) for `duration` s; returns the haptic log (columns t, x, y, z, fx, fy, "
          "fz, buttons) and statistics. Deterministic unless real_time.");
}
