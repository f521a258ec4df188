#pragma once
/// \file
/// Files a person opens to see the face data (issue #11 item 6): per performance, three VTU time
/// series for ParaView under DIR/vtk/<performance>/ (float32, every `every`-th frame):
///
///     lr_mesh.pvd    the LR tet mesh (the split lattice) as simulated
///     lr_skin.pvd    the skin embedded in it (what Embedded predicts), `distance_to_hr` (m)
///     hr_skin.pvd    the HR skin, `distance_to_lr` (m: the discrepancy of Fig. 4) and
///                    `displacement` (m, from the rest surface)
///
/// The HR volume is not in the data files (only its skin is kept per frame); its rest mesh is
/// DIR/hr_volume.msh. Open the three .pvd files together and play them.

#include <filesystem>
#include <string>
#include <vector>

#include "../../core/error.hpp"
#include "../../data/paired_frames.hpp"
#include "../../discretize/embedding.hpp"
#include "../../io/vtu.hpp"
#include "face_model.hpp"

namespace simsr::scenario {

/// Writes the three series of one performance's frames (LR mesh positions, HR skin positions) to
/// `dir`/<name>/ (file comment). ShapeError when the frames do not fit the model; ArgumentError
/// for every < 1. Returns the number of frames written per series.
template <exec::HostPolicy P>
Index write_face_vtu_series(P policy, const FaceModel& face, const data::PairedFrames<>& frames, const std::string& name, const std::filesystem::path& dir,
                            Index every = 1) {
  if (every < 1) throw ArgumentError("write_face_vtu_series: every must be ≥ 1, got " + std::to_string(every));
  const Index N = face.lr.num_vertices(), M = face.surface.num_vertices();
  if (frames.num_lr() != N || frames.num_hr() != M)
    throw ShapeError("write_face_vtu_series: frames (N, M) of '" + name + "'", {N, M}, {frames.num_lr(), frames.num_hr()});
  const auto out = dir / name;
  std::filesystem::create_directories(out);
  io::PvdWriter lr_mesh(out / "lr_mesh.pvd"), lr_skin(out / "lr_skin.pvd"), hr_skin(out / "hr_skin.pvd");
  Index written = 0;
  for (Index f = 0; f < frames.num_frames(); f += every, ++written) {
    const Points<> x = frames.lr(f);
    const Points<> lr = deform(policy, face.surface_in_lr, face.lr.T, x);
    const Points<> hr = frames.hr(f);
    const Eigen::VectorXf gap = (lr - hr).rowwise().norm().cast<float>();
    const Eigen::VectorXf moved = (hr - face.surface.V).rowwise().norm().cast<float>();
    const double t = double(frames.ids[std::size_t(f)]);
    lr_mesh.add(t, io::VtuGrid().set_points(x.cast<float>()).set_tets(face.lr.T));
    lr_skin.add(t, io::VtuGrid().set_points(lr.cast<float>()).set_triangles(face.surface.F).add_point_data("distance_to_hr", gap));
    hr_skin.add(t, io::VtuGrid()
                       .set_points(hr.cast<float>())
                       .set_triangles(face.surface.F)
                       .add_point_data("distance_to_lr", gap)
                       .add_point_data("displacement", moved));
  }
  return written;
}

/// The series of every named performance of a datagen folder: reads `data_dir`/<name>.npz and
/// writes `data_dir`/vtk/<name>/ (the files datagen wrote for this model: ShapeError otherwise).
template <exec::HostPolicy P>
void write_face_data_views(P policy, const FaceModel& face, const std::filesystem::path& data_dir, const std::vector<std::string>& performances,
                           Index every) {
  for (const auto& name : performances)
    write_face_vtu_series(policy, face, data::read_paired_frames(data_dir / (name + ".npz"), face.lr.num_vertices(), face.surface.num_vertices()), name,
                          data_dir / "vtk", every);
}

}  // namespace simsr::scenario
