// Python bindings (pybind11): load a scene or build a model from NumPy arrays, step, read positions,
// displacements, forces and energy as NumPy arrays (views without copies where the data lives in the
// simulation), drive the probe. Long calls release the GIL.
#include <pointhaptics/fem/calculix_indentation.hpp>
#include <pointhaptics/haptics/devices/virtual_device.hpp>
#include <pointhaptics/mechanics/forces.hpp>
#include <pointhaptics/io/point_cloud_file.hpp>
#include <pointhaptics/mechanics/model_builder.hpp>
#include <pointhaptics/mechanics/viscoelasticity.hpp>
#include <pointhaptics/pointhaptics.hpp>
#include <pointhaptics/core/stoppable_call.hpp>

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <csignal>
#include <mutex>
#include <optional>
#include <thread>

namespace py = pybind11;
namespace ph = pointhaptics;

namespace {

// tools or obstacles by name, as the result JSON writes them
py::dict named_loads(const std::vector<std::pair<std::string, ph::ToolSummary>>& loads) {
  const auto vec = [](const ph::Vec3& v) { return std::array<double, 3>{v.x(), v.y(), v.z()}; };
  py::dict d;
  for (const auto& [name, o] : loads) {
    py::dict block;
    block["kind"] = o.kind;
    block["position"] = vec(o.position);
    block["force"] = vec(o.force);
    block["torque"] = vec(o.torque);
    block["contacts"] = o.contacts;
    block["penetration"] = o.penetration;
    block["friction"] = vec(o.friction);
    if (o.haptic_ticks > 0) {  // a device's hand: its own haptic loop
      py::dict haptic;
      haptic["ticks"] = o.haptic_ticks;
      haptic["period_p99_us"] = o.haptic_period_p99_us;
      haptic["max_force_n"] = o.haptic_max_force_n;
      block["haptic"] = haptic;
    }
    d[py::str(name)] = block;
  }
  return d;
}

using RowPoints = py::array_t<double, py::array::c_style | py::array::forcecast>;

// A read-only (n, 3) view of a 3 x n column-major Points buffer owned by `owner`.
py::array view(const ph::Points& P, py::handle owner, Eigen::Index first = 0, Eigen::Index count = -1) {
  py::array a(py::dtype::of<double>(), {count < 0 ? P.cols() - first : count, Eigen::Index{3}},
              {Eigen::Index{3 * sizeof(double)}, Eigen::Index{sizeof(double)}}, P.col(first).data(), owner);
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

// The result JSON's blocks (solver, energy, timing, constraints, haptic, lod, model): the same keys as
// `pointhaptics run --json`, built by the same code; the per-point arrays are left out (they are the views).
py::dict summary_dict(const ph::Model& model, const ph::State& state, const ph::RunSummary& s) {
  py::dict d = py::module_::import("json").attr("loads")(ph::result_json(model, state, s));
  d.attr("pop")("points");
  return d;
}

// a name from the enum's one table (core/parameters.hpp), or an error listing the names
template <class E>
E enum_value(const char* what, const char* key, const std::string& name) {
  if (const std::optional<E> e = ph::parse_enum<E>(name)) return *e;
  throw ph::Error(fmt::format("{}: unknown {} \"{}\" (expected {})", what, key, name, ph::enum_choices<E>()));
}

// A step that failed (divergence, Newton, load stepping) is an exception in Python, as the docstrings say;
// summary() then says so too
void raise_if_failed(const ph::StepReport& report) {
  if (report.status == ph::StepStatus::FAILED) throw ph::Error(report.failure);
}

// The simulation with the scene it came from (for its probe), so that Python owns one object. Calls that
// release the GIL run concurrently with other Python threads, so every call on one object takes its mutex:
// a step and a read, or two steps, from two threads follow each other instead of sharing the state.
struct PySimulation {
  std::unique_ptr<ph::Simulation> sim;
  ph::Scene scene;
  bool from_scene = false;                            ///< scene.object describes the object (not from_points)
  ph::InteractiveOptions interactive;                 ///< with a device's [probe]: its session (run_scene())
  std::optional<ph::InteractiveResult> last_session;  ///< the last run_scene() with a device's probe, for summary()
  std::optional<ph::ObjectSurface> surface;           ///< built on the first surface_* call
  ph::Points surface_vertices;                        ///< its deformed vertices, 3 x m, kept current after every step
  std::optional<ph::CutSurface> cut;  ///< the surface split along the cuts (cut_surface(); split when they change)
  std::mutex mutex;

  // the surface's vertices follow the points (after every step, run or probe, once asked for)
  void carry_surface() {
    if (surface) ph::carry_surface(surface->map, surface->mesh.V, sim->state().u, surface_vertices);
  }
  const ph::ObjectSurface& object_surface() {
    if (!surface) {
      const ph::Model& model = sim->model();
      // from points: reconstructed from them (the half level of their kernel density), edges of half the spacing
      surface = from_scene ? ph::build_object_surface(scene, model)
                           : ph::carried_surface(ph::reconstruct_surface(model, 0.5 * model.spacing),
                                                 "reconstructed from the points", model, "the points' surface");
      carry_surface();
    }
    return *surface;
  }
};

// Ctrl-C during a long call (step, run, probe, a static solve), which runs with the GIL released: Python's own
// handler would only run once the call returned, so the call puts in one that asks the library to stop
// (run_control.hpp: every loop polls it, within 0.1 s), and raises KeyboardInterrupt when it has. Signals reach
// only the main thread's handlers; calls on other threads keep Python's.
extern "C" void stop_on_interrupt(int) { ph::request_stop(); }

class InterruptibleCall {
 public:
  InterruptibleCall() {
    ph::clear_stop_request();
    if (PyThread_get_thread_ident() != main_thread_ident) return;
    struct sigaction ours {};
    ours.sa_handler = stop_on_interrupt;
    sigemptyset(&ours.sa_mask);
    installed_ = sigaction(SIGINT, &ours, &python_) == 0;
  }
  ~InterruptibleCall() {
    if (installed_) sigaction(SIGINT, &python_, nullptr);
  }
  InterruptibleCall(const InterruptibleCall&) = delete;
  InterruptibleCall& operator=(const InterruptibleCall&) = delete;
  /// After the call, with the GIL held: KeyboardInterrupt if it was stopped (the object stays usable).
  void raise_if_stopped(bool stopped) {
    if (!stopped && !ph::stop_requested()) return;
    ph::clear_stop_request();
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  static inline unsigned long main_thread_ident = 0;

 private:
  bool installed_ = false;
  struct sigaction python_ {};
};

// A long call on the object: Ctrl-C stops it (InterruptibleCall), the GIL is released and the object's lock held
template <class Work>
void long_call(PySimulation& p, Work&& work) {
  InterruptibleCall call;
  bool stopped = false;
  {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(p.mutex);
    try {
      stopped = work();
    } catch (const ph::Interrupted&) {
      stopped = true;
    }
    p.carry_surface();
  }
  call.raise_if_stopped(stopped);
  if (p.sim->diagnostics().failed) throw ph::Error(p.sim->diagnostics().failure);
}

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

// A Python value as TOML text: numbers, booleans, strings, lists and dicts (inline tables, e.g. lod.levels =
// [{"distance": 3.0, "K": 6}]); NumPy scalars by their item(); NaN and infinities as TOML's nan and inf (which
// the scene reader then names as not finite)
std::string toml_value(const std::string& key, py::handle v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(v)) return py::str(v).cast<std::string>();
  if (py::isinstance<py::float_>(v)) {
    const double x = v.cast<double>();
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    return fmt::format("{:.17g}", x);
  }
  if (py::isinstance<py::str>(v)) return py::module_::import("json").attr("dumps")(v).cast<std::string>();
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    std::string out = "[";
    for (py::handle item : v) out += (out.size() > 1 ? ", " : "") + toml_value(key, item);
    return out + "]";
  }
  if (py::isinstance<py::dict>(v)) {
    std::string out = "{";
    for (const auto& [k, item] : v.cast<py::dict>())
      out += fmt::format("{}{} = {}", out.size() > 1 ? ", " : " ", toml_value(key, py::str(k)), toml_value(key, item));
    return out + " }";
  }
  if (py::hasattr(v, "item")) return toml_value(key, v.attr("item")());  // a NumPy scalar
  throw ph::Error(
      fmt::format("settings: {}: a value of type {} is not a scene value (numbers, booleans, strings, lists, dicts)",
                  key, py::str(py::type::of(v).attr("__name__")).cast<std::string>()));
}

// {key: value} -> scene settings
std::vector<ph::SceneSetting> settings_of(const py::object& settings) {
  std::vector<ph::SceneSetting> out;
  if (settings.is_none()) return out;
  for (const auto& [key, value] : settings.cast<py::dict>()) {
    const std::string k = py::str(key).cast<std::string>();
    out.push_back({k, toml_value(k, value)});
  }
  return out;
}

std::unique_ptr<PySimulation> open_session(ph::Scene scene, int threads) {
  auto p = std::make_unique<PySimulation>();
  ph::SessionOptions options;
  options.threads = threads;
  options.make_device = false;  // made by run_scene(), or Python drives the probe itself (probe())
  ph::SceneSession session = ph::open_scene(std::move(scene), options);
  p->scene = std::move(session.scene);
  p->sim = std::move(session.simulation);
  p->interactive = std::move(session.interactive);
  p->from_scene = true;
  return p;
}

std::unique_ptr<PySimulation> from_scene(const std::string& path, int threads, const py::object& settings) {
  return open_session(ph::read_scene_file(path, settings_of(settings)), threads);
}

std::unique_ptr<PySimulation> from_scene_text(const std::string& text, const std::string& base_dir, int threads,
                                              const py::object& settings, const std::string& name) {
  return open_session(ph::parse_scene(text, name, base_dir, settings_of(settings)), threads);
}

py::list vec_list(const ph::Vec3& v) { return py::cast(std::vector<double>{v.x(), v.y(), v.z()}); }

std::unique_ptr<PySimulation> from_points(const RowPoints& X, double spacing, py::object fixed, py::object forces,
                                          double young, double poisson, double density, double damping,
                                          const std::string& kernel, double support_factor, const std::string& solver,
                                          double dt, int threads, const std::string& model_name,
                                          const std::vector<std::pair<double, double>>& prony) {
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
  material.model = enum_value<ph::MaterialModel>("material", "model", model_name);
  for (const auto& [g, tau] : prony) material.prony.push_back({g, tau});  // build_model checks it, as every material
  if (!(young > 0 && young <= 1e13) || !(poisson > -1 && poisson < 0.5) || !(density >= 1e-3 && density <= 1e5) ||
      !(damping >= 0 && std::isfinite(damping)))
    throw ph::Error(
        "material: 0 < young <= 1e13 Pa, -1 < poisson < 0.5, 1e-3 <= density <= 1e5 kg/m^3 and damping >= 0 are "
        "needed (as in scene files)");
  ph::KernelParams k;
  k.type = enum_value<ph::KernelType>("kernel", "type", kernel);
  k.support_factor = support_factor;
  auto p = std::make_unique<PySimulation>();
  p->scene.solver.kind = enum_value<ph::SolverKind>("solver", "kind", solver);
  p->scene.solver.dt = dt;
  ph::Model model = ph::build_model(cloud, material, k);
  if (!fixed.is_none()) {
    const auto mask = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(fixed);
    if (!mask || mask.ndim() != 1 || mask.shape(0) != model.n_points)
      throw ph::Error("fixed: expected a boolean array of n values");
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
  // NumPy's C API, looked up now, with the GIL held and no other thread in this module: pybind11 looks it up on
  // first use behind a static guard, and a first use by a thread while another waited for the object's lock
  // deadlocked (issue 52: the guard's holder needed the GIL that the waiter held)
  py::module_::import("numpy");
  (void)py::detail::npy_api::get();
  (void)py::array_t<double>(0);
  (void)py::array_t<long long>(0);
  (void)py::array_t<bool>(0);
  InterruptibleCall::main_thread_ident =
      py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  // a Ctrl-C leaves an uninterruptible library call (CHOLMOD's factorisation) ending on a thread of its own
  // (core/stoppable_call.hpp): the interpreter waits for it before it exits, so that no static destructor (the
  // BLAS's buffers) runs under it
  py::module_::import("atexit").attr("register")(py::cpp_function([] {
    const py::gil_scoped_release unlocked;
    while (ph::abandoned_work_running() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }));

  m.attr("__version__") = "0.1.0";
  m.def(
      "calculix_indentation",
      [](const std::vector<double>& depths, double sphere_radius, double block_radius, double height, double young,
         double poisson, const std::string& model, int elements_per_radius, int threads) {
        if (depths.empty()) throw ph::Error("calculix_indentation: depths are needed (m)");
        ph::fem::IndentationProblem problem;
        problem.sphere_radius = sphere_radius;
        problem.block_radius = block_radius;
        problem.height = height;
        problem.material.young = young;
        problem.material.poisson = poisson;
        problem.material.model = enum_value<ph::MaterialModel>("calculix_indentation", "model", model);
        problem.elements_per_radius = elements_per_radius;
        double deepest = 0;
        for (double d : depths) {
          if (!(d >= 0) || !std::isfinite(d)) throw ph::Error("calculix_indentation: depths must be >= 0 (m)");
          deepest = std::max(deepest, d);
        }
        problem.max_depth = deepest;
        problem.increments = std::max(6, static_cast<int>(depths.size()));
        ph::fem::IndentationSolution solution;
        {
          py::gil_scoped_release release;
          solution = ph::fem::solve_indentation(problem, threads);
        }
        std::vector<double> forces;
        for (double d : depths) forces.push_back(d > 0 ? solution.force_at(d) : 0.0);
        return forces;
      },
      py::arg("depths"), py::arg("sphere_radius") = 0.01, py::arg("block_radius") = 0.04, py::arg("height") = 0.04,
      py::arg("young") = 1e5, py::arg("poisson") = 0.3, py::arg("model") = "neo_hookean",
      py::arg("elements_per_radius") = 20, py::arg("threads") = 1,
      "CalculiX's force (N) of a rigid frictionless sphere (sphere_radius, m) pressed into a cylinder (block_radius, "
      "height; m; bottom held) to each of `depths` (m): an axisymmetric CAX8 model, NLGEOM, with the material "
      "`model` (svk | neo_hookean | mooney_rivlin with young and poisson its small-strain moduli), elements of "
      "R / elements_per_radius at the contact (`pointhaptics experiment contact` shows its convergence). Needs ccx "
      "(Debian's calculix-ccx). Releases the GIL.");
  py::class_<PySimulation>(m, "Simulation", R"doc(A deformable object made of points, its state and its solver.

Make one with Simulation.from_scene(path) (a scene file, as `pointhaptics run` reads) or
Simulation.from_points(points, spacing, ...) (NumPy arrays). Units are SI throughout: m, s, N, Pa, kg, J.
Arrays have one row per point of the object, n rows: reference, displacement and velocity are read-only
views into the simulation (they follow it as it steps); positions and forces are copies. With levels of
detail only the points near the contact are simulated; the others follow or keep their displacement, and
every array still speaks of all n points.

Calls on one Simulation from several threads follow each other (each object has a lock); step(), run() and
probe() release the GIL while they work. Errors are pointhaptics.Error (a ValueError) with a message that
names the problem.)doc")
      .def_static(
          "from_scene", &from_scene, py::arg("path"), py::arg("threads") = 0, py::arg("settings") = py::none(),
          "Load a scene file (TOML: [object], [material], [kernel], [solver], [[fixed]], [[load]], [lod] ...) and "
          "prepare its simulation, with its levels of detail. threads: of the force evaluation (0: all). settings: "
          "{key: value} set over the file's, as `pointhaptics run --set` (e.g. {'material.young': 2e5, "
          "'load.0.total': [0, -0.02, 0]}).")
      .def_static(
          "from_scene_text", &from_scene_text, py::arg("text"), py::arg("base_dir") = ".", py::arg("threads") = 0,
          py::arg("settings") = py::none(), py::arg("name") = "<string>",
          "As from_scene, from the scene's text: relative file paths are taken from base_dir, and messages name "
          "`name` for the file (what a study sends to its workers).")
      .def("__reduce__",
           [](const PySimulation&) -> py::object {
             throw ph::Error(
                 "a Simulation does not travel to another process: send its scene (path or text) and settings, "
                 "and open it there (pointhaptics.study does)");
           })
      .def_static(
          "from_points", &from_points, py::arg("points"), py::arg("spacing"), py::arg("fixed") = py::none(),
          py::arg("forces") = py::none(), py::arg("young") = 1e5, py::arg("poisson") = 0.4, py::arg("density") = 1000.0,
          py::arg("damping") = 0.0, py::arg("kernel") = "poly6", py::arg("support_factor") = 2.0,
          py::arg("solver") = "explicit", py::arg("dt") = 1e-3, py::arg("threads") = 0, py::arg("model") = "svk",
          py::arg("prony") = std::vector<std::pair<double, double>>{},
          "Build a model from an (n, 3) array of points (m) sampled at `spacing`, with an optional boolean "
          "`fixed` mask and (n, 3) constant `forces` (N); `model`: svk | neo_hookean | mooney_rivlin | corotated "
          "(young and poisson are its small-strain moduli); `prony`: [(g, tau), ...], a viscoelastic shear part "
          "(young and poisson then the instantaneous moduli). Scene files take every material key, [[region]] too.")
      .def(
          "step",
          [](PySimulation& p) {
            ph::StepReport report;
            long_call(p, [&] {
              report = p.sim->step();
              return false;
            });
            raise_if_failed(report);
          },
          "Advance by one solver step: dt of explicit dynamics (sub-stepped below the stable step) or implicit "
          "dynamics; a static solver solves for the equilibrium under the full load. Raises pointhaptics.Error on a "
          "divergence or a failed solve (then summary() says so). Releases the GIL.")
      .def(
          "run",
          [](PySimulation& p, double duration) {
            // (a duration that is not one, or too long, is refused by run() before it steps)
            long_call(p, [&] {
              p.sim->run(duration);
              return false;
            });
          },
          py::arg("duration"),
          "Step until `duration` seconds more have passed (static: solve once); stops at a failed step and raises "
          "pointhaptics.Error (summary() then says so); releases the GIL")
      .def_property_readonly(
          "time",
          [](PySimulation& p) {
            const auto lock = locked(p);
            return p.sim->state().time;
          },
          "Simulated time so far (s)")
      .def_property_readonly(
          "n_points", [](PySimulation& p) { return p.sim->model().n_points; }, "Points of the object, n")
      .def("__repr__",
           [](PySimulation& p) {
             const auto lock = locked(p);
             const ph::Model& m = p.sim->simulated_model();
             std::string lod;
             if (const ph::ActiveSet* a = p.sim->active_set())
               lod = ", " + std::to_string(a->n_selected) + " simulated";
             return "<pointhaptics.Simulation: " + std::to_string(m.n_points) + " points" + lod + ", " +
                    std::string(ph::to_string(p.sim->solver().kind)) +
                    " solver, dt = " + fmt::format("{:g}", p.sim->solver().dt) +
                    " s, t = " + fmt::format("{:g}", p.sim->state().time) + " s>";
           })
      .def_property_readonly(
          "reference", [](py::object self) { return view(self.cast<PySimulation&>().sim->model().X, self); },
          "Reference (rest) positions X, an (n, 3) read-only view (m)")
      .def_property_readonly(
          "displacement",
          [](py::object self) {
            PySimulation& p = self.cast<PySimulation&>();
            const auto lock = locked(p);
            return view(p.sim->state().u, self);
          },
          "Displacements, an (n, 3) read-only view into the simulation (m): it changes as the simulation steps")
      .def_property_readonly(
          "velocity",
          [](py::object self) {
            PySimulation& p = self.cast<PySimulation&>();
            const auto lock = locked(p);
            return view(p.sim->state().velocity, self);
          },
          "Velocities, an (n, 3) read-only view (m/s)")
      .def_property_readonly(
          "positions",
          [](PySimulation& p) {
            const auto lock = locked(p);
            const ph::Points x = p.sim->model().X + p.sim->state().u;
            return py::array_t<double>({x.cols(), Eigen::Index{3}},
                                       {Eigen::Index{3 * sizeof(double)}, Eigen::Index{sizeof(double)}}, x.data());
          },
          "Current positions X + u, an (n, 3) array (a copy)")
      .def_property_readonly(
          "forces",
          [](PySimulation& p) {
            const auto lock = locked(p);
            const ph::Model& m = p.sim->simulated_model();
            ph::Workspace ws(m, 1);
            ph::viscous_stress_at_state(m, p.sim->simulated_state(), ws,
                                        p.sim->solver().kind == ph::SolverKind::STATIC);
            ph::compute_internal_forces(m, p.sim->simulated_state().u, ws);
            // one row per point of the object, as every other array (with levels of detail the simulated
            // points carry theirs, the others none)
            ph::Points f = ph::Points::Zero(3, p.sim->model().n_points);
            const ph::ActiveSet* active = p.sim->active_set();
            for (ph::index_t k = 0; k < m.n_points; ++k) f.col(active ? active->full_of[k] : k) = ws.f_int.col(k);
            return py::array_t<double>({f.cols(), Eigen::Index{3}},
                                       {Eigen::Index{3 * sizeof(double)}, Eigen::Index{sizeof(double)}}, f.data());
          },
          "Internal elastic forces, an (n, 3) array (a copy; N), one row per point of the object like every other "
          "array; with levels of detail, zero on the points not simulated")
      .def_property_readonly(
          "fixed",
          [](PySimulation& p) {
            const ph::Model& m = p.sim->simulated_model();
            py::array_t<bool> a(m.n_points);
            for (ph::index_t i = 0; i < m.n_points; ++i) a.mutable_at(i) = m.fixed[i] != 0;
            return a;
          },
          "Held points, an (n,) boolean array (a copy): the [[fixed]] boxes or the `fixed` mask")
      .def_property_readonly(
          "surface_vertices",
          [](py::object self) {
            PySimulation& p = self.cast<PySimulation&>();
            const auto lock = locked(p);
            p.object_surface();
            return view(p.surface_vertices, self);
          },
          "The object's surface (docs/surface.md): its deformed vertices, an (m, 3) read-only view (m) that follows the "
          "simulation as it steps. Boxes, spheres and half-spheres have their exact boundary, surface meshes their own, "
          "point clouds, volume images and Simulations from_points one reconstructed from the points; built on first use.")
      .def_property_readonly(
          "surface_triangles",
          [](PySimulation& p) {
            const auto lock = locked(p);
            const ph::ObjectSurface& surface = p.object_surface();
            py::array_t<std::int64_t> a({static_cast<py::ssize_t>(surface.mesh.F.size()), py::ssize_t{3}});
            auto w = a.mutable_unchecked<2>();
            for (std::size_t t = 0; t < surface.mesh.F.size(); ++t)
              for (int k = 0; k < 3; ++k)
                w(static_cast<py::ssize_t>(t), k) = surface.mesh.F[t][static_cast<std::size_t>(k)];
            return a;
          },
          "The object's surface triangles, a (t, 3) integer array of rows of surface_vertices (a copy), counter-clockwise "
          "seen from outside")
      .def(
          "cut_surface",
          [](PySimulation& p) {
            const auto lock = locked(p);
            if (!p.cut) p.cut.emplace(p.object_surface());
            const ph::ObjectSurface& split = p.cut->at(p.sim->model(), p.sim->cut_sheets());
            const ph::Points y = ph::deformed_surface(split, p.sim->state().u);
            py::array_t<double> vertices({static_cast<py::ssize_t>(y.cols()), py::ssize_t{3}});
            auto v = vertices.mutable_unchecked<2>();
            for (Eigen::Index k = 0; k < y.cols(); ++k)
              for (int a = 0; a < 3; ++a) v(static_cast<py::ssize_t>(k), a) = y(a, k);
            py::array_t<std::int64_t> triangles({static_cast<py::ssize_t>(split.mesh.F.size()), py::ssize_t{3}});
            auto t = triangles.mutable_unchecked<2>();
            for (std::size_t f = 0; f < split.mesh.F.size(); ++f)
              for (int k = 0; k < 3; ++k)
                t(static_cast<py::ssize_t>(f), k) = split.mesh.F[f][static_cast<std::size_t>(k)];
            return py::make_tuple(vertices, triangles, static_cast<long long>(split.cut_faces));
          },
          "The object's surface split along the cuts so far (docs/cutting.md): (vertices, triangles, cut_faces), copies "
          "at the current state; the last cut_faces triangles are the faces of the cuts (with several bodies, each cut "
          "body's come last among its own). Without cuts, the surface of "
          "surface_vertices and surface_triangles (whose size stays as it was built: they stay the uncut surface).")
      .def(
          "run_scene",
          [](PySimulation& p) {
            if (!p.from_scene)
              throw ph::Error("run_scene: this Simulation was made from_points; it has no scene to run");
            long_call(p, [&] {
              if (p.scene.probe.present && !p.scene.probe.held()) {
                // a device's probe: its session in simulated time (`pointhaptics run --deterministic`)
                const std::unique_ptr<ph::Device> device = ph::make_scene_device(p.scene);
                ph::InteractiveOptions options = p.interactive;
                const auto other_devices = ph::make_other_hand_devices(p.scene, options);
                options.real_time = false;
                options.log = false;
                p.last_session = ph::run_interactive(*p.sim, *device, options);
                return p.last_session->interrupted;
              }
              p.sim->run(p.scene.solver.duration);
              return false;
            });
          },
          "Run the scene as `pointhaptics run --deterministic` does: solver.duration seconds of dynamics, or the static "
          "solve, or with a device's [probe] its session in simulated time. Raises pointhaptics.Error on a failed step; "
          "releases the GIL.")
      .def_property_readonly(
          "duration", [](PySimulation& p) { return p.scene.solver.duration; }, "The scene's solver.duration (s)")
      .def(
          "hold_tool",
          [](PySimulation& p, const std::array<double, 3>& position) {
            const auto lock = locked(p);
            ph::HeldTool* tool = p.sim->held_tool();
            if (!tool) throw ph::Error("hold_tool: the scene holds no tool ([probe] position = [x, y, z])");
            const ph::Vec3 x(position[0], position[1], position[2]);
            if (!x.allFinite()) throw ph::Error("hold_tool: the position is not finite");
            p.sim->set_tool_pose(ph::ToolPose{x, tool->pose().orientation});
          },
          py::arg("position"),
          "Move the held tool ([probe] position) to `position` (scene axes, m), keeping its orientation; the next step "
          "(static: the equilibrium) starts from the state reached, so a force-depth curve is a sequence of "
          "hold_tool() and step().")
      .def_property_readonly(
          "tool",
          [](PySimulation& p) -> py::object {
            const auto lock = locked(p);
            ph::ToolSummary t = p.last_session ? p.last_session->tool : p.sim->tool_summary();
            if (!t.present) return py::none();
            py::dict d;
            d["kind"] = t.kind;
            d["position"] = vec_list(t.position);
            d["force"] = vec_list(t.force);
            d["torque"] = vec_list(t.torque);
            d["friction"] = vec_list(t.friction);
            d["contacts"] = t.contacts;
            d["penetration"] = t.penetration;
            if (p.scene.probe.held()) {
              d["start"] = vec_list(p.scene.probe.position);
              d["direction"] = vec_list(p.scene.probe.direction);
            }
            return d;
          },
          "The tool now (None without one), as the result JSON's tool block: kind, position (m), force (N, the object "
          "on the tool, scene axes), torque (N m), friction (N), contacts, penetration (m); a held tool adds start "
          "(its scene position) and direction (the unit vector it presses along, [probe] direction).")
      .def(
          "energy",
          [](PySimulation& p) {
            const auto lock = locked(p);
            const ph::EnergyTerms e = ph::strain_energy(p.sim->simulated_model(), p.sim->simulated_state().u);
            py::dict d;
            d["strain"] = e.total();
            d["kinetic"] = ph::kinetic_energy(p.sim->simulated_model(), p.sim->simulated_state().velocity);
            return d;
          },
          "Energies of the simulated points now, a dict: strain (the elastic energy whose gradient the forces are) and "
          "kinetic (J)")
      .def_property_readonly(
          "obstacles",
          [](PySimulation& p) {
            const auto lock = locked(p);
            return named_loads(p.sim->summary().obstacles);
          },
          "The scene's [[obstacle]] bodies by name, each a dict as the result JSON's obstacles block: kind, position, "
          "force (what the object exerts on it now, N), torque, contacts, penetration (m), friction (N)")
      .def_property_readonly(
          "tools",
          [](PySimulation& p) {
            const auto lock = locked(p);
            ph::RunSummary summary = p.sim->summary();
            // after run_scene() with devices: each hand as the session left it
            if (p.last_session) ph::add_interactive_summary(summary, *p.last_session);
            if (summary.tool.present) summary.tools.insert(summary.tools.begin(), {summary.tool_name, summary.tool});
            return named_loads(summary.tools);
          },
          "The scene's tools by name ([[tool]] tables; a [probe] as \"probe\"; after run_scene() every device-driven "
          "hand as its session ended), each a dict as the result JSON's tools block: kind, position (m), force (what "
          "the object exerts on it now, N), torque (N m), contacts, penetration (m), friction (N)")
      .def_property_readonly(
          "bodies",
          [](py::object self) {
            PySimulation& p = self.cast<PySimulation&>();
            const auto lock = locked(p);
            const ph::Model& m = p.sim->model();
            const ph::RunSummary summary = p.sim->summary();
            const auto vec = [](const ph::Vec3& v) { return std::array<double, 3>{v.x(), v.y(), v.z()}; };
            py::dict d;
            for (std::size_t k = 0; k < summary.bodies.size(); ++k) {
              const ph::BodySummary& b = summary.bodies[k];
              const Eigen::Index first = m.body_start[k];
              py::dict block;
              block["first_point"] = first;
              block["points"] = b.points;
              block["mass"] = b.mass;
              block["contact_force"] = vec(b.contact_force);
              block["mean_displacement"] = vec(b.mean_displacement);
              block["max_displacement"] = b.max_displacement;
              block["asleep"] = b.asleep;
              block["slept_steps"] = b.slept_steps;
              block["reference"] = view(m.X, self, first, b.points);
              block["displacement"] = view(p.sim->state().u, self, first, b.points);
              block["velocity"] = view(p.sim->state().velocity, self, first, b.points);
              d[py::str(b.name)] = block;
            }
            return d;
          },
          "With several [[object]] tables, each body by name, a dict: first_point and points (its rows in the "
          "object's arrays), mass (kg), contact_force (what the other bodies exert on it now, N), mean_displacement "
          "(its centre of mass's, m), max_displacement (m), asleep and slept_steps (explicit steps: a body at rest that "
          "nothing touches sleeps), and its rows of reference, displacement and velocity as read-only (points, 3) "
          "views. Empty with one object.")
      .def(
          "summary",
          [](PySimulation& p) {
            const auto lock = locked(p);
            ph::RunSummary summary = p.sim->summary();
            if (p.last_session) ph::add_interactive_summary(summary, *p.last_session);
            return summary_dict(p.sim->model(), p.sim->state(), summary);
          },
          "The run so far, with the result JSON's blocks and keys (`pointhaptics run --json`): solver (kind, converged, "
          "iterations, residual, steps, substeps, stable_dt, cg_iterations, failure, interrupted), energy (strain, kinetic; "
          "J), timing (wall_s, step_ms_mean, steps_per_s), constraints (per held group: points, reaction in N), haptic, "
          "lod, model. A step that raised leaves converged False and its message in solver.failure.")
      .def(
          "probe",
          [](PySimulation& p, const std::vector<std::vector<double>>& keyframes, double radius, const std::string& mode,
             double duration, bool real_time) {
            if (keyframes.empty()) throw ph::Error("probe: keyframes [[t, x, y, z(, button)], ...] are needed");
            // as in scene files: [t, x, y, z] or [t, x, y, z, button]
            std::vector<ph::Keyframe> frames;
            for (std::size_t k = 0; k < keyframes.size(); ++k) {
              const std::vector<double>& f = keyframes[k];
              if (f.size() != 4 && f.size() != 5)
                throw ph::Error("probe: keyframe " + std::to_string(k) + " has " + std::to_string(f.size()) +
                                " values; expected [t, x, y, z] or [t, x, y, z, button]");
              frames.push_back({f[0], ph::Vec3(f[1], f[2], f[3]), f.size() == 5 && f[4] != 0});
            }
            ph::VirtualDevice device(ph::Trajectory(std::move(frames)), ph::known_device_specs("touch"));
            ph::Scene scene = p.scene;
            scene.probe.present = true;
            scene.probe.radius = radius;
            if (mode != "push" && mode != "grab") throw ph::Error("probe: mode must be push or grab");
            scene.probe.grab = mode == "grab";
            scene.solver.duration = duration;
            ph::InteractiveOptions o = ph::scene_interactive_options(scene, p.sim->model());
            o.other_hands.clear();  // this probe alone
            o.real_time = real_time;
            ph::InteractiveResult r;
            long_call(p, [&] {
              // the probe pushes on the object's surface (with levels of detail, on the part the active set carries)
              o.surface = std::make_shared<const ph::ObjectSurface>(p.object_surface());
              r = ph::run_interactive(*p.sim, device, o);
              return r.interrupted;
            });
            // the columns of --force-log: t, x, y, z, vx, vy, vz, buttons, fx, fy, fz, tx, ty, tz
            py::array_t<double> log({static_cast<py::ssize_t>(r.log.size()), py::ssize_t{14}});
            auto w = log.mutable_unchecked<2>();
            for (std::size_t k = 0; k < r.log.size(); ++k) {
              const ph::HapticLogRow& row = r.log[k];
              const double v[14] = {row.t,
                                    row.position.x(),
                                    row.position.y(),
                                    row.position.z(),
                                    row.velocity.x(),
                                    row.velocity.y(),
                                    row.velocity.z(),
                                    static_cast<double>(row.buttons),
                                    row.force.x(),
                                    row.force.y(),
                                    row.force.z(),
                                    row.torque.x(),
                                    row.torque.y(),
                                    row.torque.z()};
              for (int c = 0; c < 14; ++c) w(static_cast<py::ssize_t>(k), c) = v[c];
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
          "Drive a spherical probe (radius in m; mode push or grab) with a virtual hand through keyframes "
          "[t, x, y, z] or [t, x, y, z, button] (s, m; device frame, whose origin is two radii above the object's top "
          "centre) for `duration` s. This advances the simulation by `duration`. Returns a dict: log, an (ticks, 14) "
          "array with the columns of --force-log (t, x, y, z, vx, vy, vz, buttons, fx, fy, fz, tx, ty, tz; s, m, m/s, bit "
          "mask, N, N m), "
          "ticks, max_force (N), max_contacts and simulation_steps. Deterministic (simulated time) unless real_time.");
}
