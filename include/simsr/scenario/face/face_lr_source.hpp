#pragma once
/// \file
/// The face's LR simulation as a live frame source (pipeline::FrameSource): a performance played
/// frame by frame on the LR mesh, from the settled neutral, as datagen simulates it (the same
/// warm start and Newton options, so its frames are datagen's LR frames of that performance).
///
///     scenario::FaceLrSource<> source(exec::omp, face, performance);   // solves the neutral once
///     pipeline::run_live(exec::omp, source, net, face.lr.V, face.surface.V, sink);

#include <string>

#include "../../core/error.hpp"
#include "face_model.hpp"
#include "face_simulator.hpp"
#include "performances.hpp"

namespace simsr::scenario {

template <class Linear = physics::ConjugateGradient<physics::Multigrid<>>>
class FaceLrSource {
 public:
  template <exec::HostPolicy P>
  FaceLrSource(P policy, const FaceModel& face, Performance performance, FaceSimulationOptions options = {})
      : face_(&face), perf_(std::move(performance)), sim_(policy, face, FaceResolution::low, std::move(options)) {
    if (perf_.num_frames() < 1) throw ArgumentError("FaceLrSource: performance '" + perf_.name + "' has no frames");
    for (Index f = 0; f < perf_.num_frames(); ++f) (void)face_controls(perf_, f, face);  // every row checked before the first frame
    sim_.set_controls(neutral_controls(face));
    solve(policy, "the neutral");
    sim_.set_positions(sim_.positions());
  }

  Index num_frames() const { return perf_.num_frames(); }
  Index num_vertices() const { return face_->lr.num_vertices(); }
  const Performance& performance() const { return perf_; }
  Index frames_done() const { return next_; }

  /// Simulates the next frame; x gets the LR mesh positions. ConvergenceError-based failures and
  /// inverted tets are an Error naming the performance and the frame.
  template <exec::HostPolicy P>
  void next(P policy, Points<Scalar>& x) {
    if (next_ >= perf_.num_frames()) throw ArgumentError("FaceLrSource: performance '" + perf_.name + "' has only " + std::to_string(perf_.num_frames()) + " frames");
    sim_.set_controls(face_controls(perf_, next_, *face_));
    solve(policy, "frame " + std::to_string(next_));
    x = sim_.positions();
    ++next_;
  }

 private:
  template <class P>
  void solve(P policy, const std::string& what) {
    try {
      sim_.step(policy);
    } catch (const ConvergenceError& e) {
      throw Error("FaceLrSource: performance '" + perf_.name + "', " + what + ": the LR solve failed: " + e.what());
    }
    if (const Index inv = sim_.count_inverted(policy))
      throw Error("FaceLrSource: performance '" + perf_.name + "', " + what + ": " + std::to_string(inv) + " LR tets inverted after the solve");
  }

  const FaceModel* face_;
  Performance perf_;
  FaceSimulator<Linear> sim_;
  Index next_ = 0;
};

}  // namespace simsr::scenario
