#pragma once
/// \file
/// The face's paired data over MPI ranks (`mpirun -np R simsr datagen --scenario face`), shared
/// by performance: every rank builds the model (the same mesh: tetgen and the lattice are
/// deterministic; tetgen works in a folder of its own per rank), rank r simulates shard r of R, a
/// contiguous block of the performances, into the run's folder (each performance's file and
/// checkpoints written atomically, as the single-process run writes them); once every rank is
/// done, rank 0 takes every performance's file as finished (generate_face_data reuses them) and
/// writes the VTU series, the unseen-force frames and face_data.json. Each performance starts
/// from the settled neutral, so the files equal the single-process run's bitwise. A killed rank
/// loses only the frames since its performance's last checkpoint; a rerun (any number of ranks)
/// resumes. The summary's per-performance timings are those of the rank that simulated it, and
/// it adds `ranks`.
///
/// Not shared yet: the frames within one performance (so R ranks help up to R performances).
///
///     auto report = mpi::generate_face_dataset(exec::omp, comm, options, "out/face", log);

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../io/atomic_file.hpp"
#include "../scenario/face/face_dataset.hpp"
#include "communicator.hpp"

namespace simsr::mpi {

namespace detail {

inline nlohmann::json stats_json(const std::vector<scenario::PerformanceStats>& stats) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& s : stats)
    a.push_back({{"name", s.name}, {"simulated", s.simulated}, {"reused", s.reused}, {"lr_seconds", s.lr_seconds}, {"hr_seconds", s.hr_seconds},
                 {"lr_iterations", s.lr_iterations}, {"hr_iterations", s.hr_iterations}});
  return a;
}

}  // namespace detail

/// The face data set of `o`, every rank taking part; every rank returns rank 0's summary. `log`
/// gets this rank's progress lines.
template <exec::HostPolicy P>
nlohmann::ordered_json generate_face_dataset(P policy, const Communicator& comm, const scenario::FaceDatasetOptions& o, const std::filesystem::path& out,
                                             const std::function<void(const std::string&)>& log = {}) {
  if (comm.size() == 1) return scenario::generate_face_dataset(policy, o, out, log);
  const auto mesh_dir = comm.is_root() ? out / "mesh" : out / "mesh" / (".rank_" + std::to_string(comm.rank()));
  const scenario::FaceDatasetParts parts = scenario::prepare_face_dataset(policy, o, out, log, mesh_dir);
  const auto mine = scenario::simulate_face_dataset(policy, parts, o, out, log, comm.shard());
  return nlohmann::ordered_json::parse(finish_on_root(comm, detail::stats_json(mine).dump(), [&](const std::vector<std::string>& all) {
    auto stats = scenario::simulate_face_dataset(policy, parts, o, out, {});  // every performance's file is there: reused
    for (const auto& text : all)
      for (const auto& r : nlohmann::json::parse(text))
        for (auto& s : stats)
          if (s.name == r["name"].get<std::string>()) {  // the rank that simulated it: its timings and what it did
            s.simulated = r["simulated"].get<Index>();
            s.reused = r["reused"].get<bool>();
            s.lr_seconds = r["lr_seconds"].get<double>();
            s.hr_seconds = r["hr_seconds"].get<double>();
            s.lr_iterations = r["lr_iterations"].get<Index>();
            s.hr_iterations = r["hr_iterations"].get<Index>();
          }
    return scenario::finish_face_dataset(policy, parts, stats, o, out, log, {{"ranks", comm.size()}}).dump();
  }));
}

}  // namespace simsr::mpi
