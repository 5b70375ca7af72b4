#pragma once
/// @file Levels of detail as a layer (seed §3): it owns the object's model and state and the index map of
/// the active set (ActiveSet::full_of / active_of), and drives an ordinary ModelSimulation of the active
/// model, re-selecting it as the contact moves. Simulation puts it between the caller and the pipeline.
#include <pointhaptics/io/result_json.hpp>
#include <pointhaptics/geometry/kd_tree.hpp>
#include <pointhaptics/lod/active_set.hpp>
#include <pointhaptics/world/model_simulation.hpp>

#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

namespace pointhaptics {

/// A selection and its active model, ready to take over (built on a worker thread or in place).
struct LodBuild {
  Selection selection;
  ActiveSet active;
  Vec3 centre;
  long long object_cuts = 0;  ///< the object's cuts it was built after (LevelsOfDetail::object_cuts_made_)
  double stable_dt = 0;
  double ms = 0;  ///< selection, active model and its stable step
  /// On a worker, with a probe on the surface: the part of `part_of` (the probe's surface when the build
  /// began) the active set carries, made there too (6 ms of a 9.7 ms take-over on the shipped half-sphere)
  std::shared_ptr<const ObjectSurface> part_of;
  std::optional<ActiveSurface> part;
};

class LevelsOfDetail {
 public:
  /// Take over the object's simulation: its model, state, diagnostics and probe carry over to the active
  /// model selected around `contact` (reference configuration, m; snapped to the nearest point). Throws
  /// Error on bad parameters or a non-finite contact.
  LevelsOfDetail(ModelSimulation&& object, const LodParams& params, const Vec3& contact);
  ~LevelsOfDetail();  ///< waits for a build in flight (it reads the object's model)

  /// The simulation of the active model (its indices are the active set's).
  ModelSimulation& active() { return *active_; }
  const ModelSimulation& active() const { return *active_; }
  const Model& object_model() const { return full_; }
  /// The object's state: the active state carried back (absorbed points follow their selected point by
  /// first-order MLS, the rest keep their last displacement, at rest); recomputed after a step, when asked.
  const State& object_state() const;
  /// Replace the object's state; the active set takes its points' values.
  void set_object_state(const State& state);
  /// The active state changed (a step): the object's is recomputed when next asked for.
  void mark_stale() { object_state_current_ = false; }
  /// After the active model was cut (a step's blade, a scripted cut, Simulation::cut): the cut reaches the
  /// object. The pairs the active model lost, where the object has them, and the object's pairs that cross the
  /// cuts' new sheets (reference configuration) are severed in the object's model, at once, or once a
  /// re-selection in flight (which reads it) is built; every later active set is built with them severed.
  void carry_cuts();
  /// The object's model with every cut carried (waits for a re-selection in flight).
  const Model& settled_object_model();

  /// The pipeline's active-set stage: follow the probe's contact point as the last step left it (contact
  /// onset, or moved by more than params.reselect h), re-selecting in place or on a worker thread as the
  /// probe was attached.
  void follow_probe();
  /// Re-select when the contact point is farther than params.reselect h from the one of the last
  /// selection (and params.reselect_interval has passed), or at contact onset (`onset`) when it is
  /// farther than a quarter of that. The state carries over without adding energy. `asynchronous`: built
  /// on a worker thread while the old set keeps stepping; taken over at the first call after it is ready.
  /// Returns the new active index of each old active point (-1 if no longer simulated) when a new active
  /// set took over, else an empty vector. Allocates (a new model): not a per-step operation.
  std::vector<index_t> update(const Vec3& contact, bool onset, bool asynchronous);
  /// The contact point of a probe for update(), in the reference configuration: when grabbing (`grabbed`:
  /// active indices), where the grabbed points are in the object; when pushing, the probe carried back by
  /// the mean displacement of the `touched` points (the probe itself if none).
  Vec3 contact_of_probe(const Vec3& probe, const std::vector<index_t>& grabbed,
                        const std::vector<index_t>& touched) const;

  const ActiveSet& active_set() const { return active_set_; }
  const Selection& selection() const { return selection_; }
  long long selections() const { return selections_; }
  /// The levels-of-detail block of the result.
  void fill(LodSummary& summary) const;

 private:
  std::vector<index_t> take_over(LodBuild build, bool built_here);
  void apply_object_cuts();
  Vec3 snap(const Vec3& c) const;

  Model full_;
  mutable State full_state_;
  mutable bool object_state_current_ = true;
  SolverSpec solver_;
  int n_threads_ = 0;
  std::unique_ptr<KdTree> tree_;  ///< over full_.X, for snapping contact points
  LodParams params_;
  std::unique_ptr<ModelSimulation> active_;
  ActiveSet active_set_;
  Selection selection_;
  Vec3 centre_ = Vec3::Constant(NAN);   ///< of the selection: the object's point nearest the contact
  Vec3 contact_ = Vec3::Constant(NAN);  ///< the contact point the selection was made for
  long long selections_ = 0;
  double last_build_ms_ = 0, max_reselect_ms_ = 0;
  std::future<LodBuild> pending_;     ///< an asynchronous re-selection in flight
  std::vector<index_t> object_cuts_;  ///< the object's pairs to sever once no re-selection reads its model
  long long object_cuts_made_ = 0;    ///< times the object's model was cut
  std::size_t sheets_carried_ = 0;    ///< sheet triangles whose pairs were found in the object
  long long sheet_revision_carried_ = 0;
  double last_selection_time_ = -std::numeric_limits<double>::infinity();  ///< of the last take-over, s
};

}  // namespace pointhaptics
