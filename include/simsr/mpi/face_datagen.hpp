#pragma once
/// \file
/// The face's paired data over MPI ranks (`mpirun -np R simsr datagen --scenario face`), shared
/// by unit of work: a performance, or a chunk of its frames when there are fewer performances than
/// ranks (o.chunks = 0, the default: ⌈R / P⌉ contiguous chunks per performance, each after its
/// warm-start lead-in, scenario/face/face_datagen.hpp). Every rank builds the model (the same
/// mesh: tetgen and the lattice are deterministic; tetgen works in a folder of its own per rank);
/// rank r simulates shard r of R, a contiguous block of the units, into the run's folder (each
/// performance's file, each chunk's part and every checkpoint written atomically, as the
/// single-process run writes them); once every rank is done, rank 0 runs the whole list, which
/// takes every performance's file as finished and assembles the chunked ones from their parts,
/// then writes the VTU series, the unseen-force frames and face_data.json.
///
/// What equals the single-process run: with one chunk per performance (R ≤ P, or o.chunks = 1)
/// every file bitwise, since each performance starts from the settled neutral; with chunks, the
/// first chunk of each performance and every chunk whose lead-in reaches frame 0 bitwise, the
/// other chunks' frames to the solver tolerance (the same equilibria from another warm start;
/// tests/mpi/test_face_datagen.cpp measures them). A killed rank loses only the frames since its
/// unit's last checkpoint; a rerun (any number of ranks; the same chunks resume chunk parts)
/// resumes. The summary's per-performance timings add up the ranks that simulated it, and it adds
/// `ranks` and `chunks_per_performance`.
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
                 {"lr_iterations", s.lr_iterations}, {"hr_iterations", s.hr_iterations}, {"lead_in_frames", s.lead_in_frames},
                 {"lead_in_seconds", s.lead_in_seconds}});
  return a;
}

/// Rank 0's figures of the whole list (`stats`: files reused or assembled) with what the ranks
/// did (`ranks`: each rank's stats_json): frames, seconds, iterations and lead-ins added over the
/// ranks that had a unit of the performance; reused when none simulated a frame of it and all
/// of them found its file finished.
inline void add_rank_stats(std::vector<scenario::PerformanceStats>& stats, const std::vector<std::string>& ranks) {
  for (auto& s : stats) {
    s.simulated = s.lr_iterations = s.hr_iterations = s.lead_in_frames = 0;
    s.lr_seconds = s.hr_seconds = s.lead_in_seconds = 0;
    bool all_reused = true;
    for (const auto& text : ranks)
      for (const auto& r : nlohmann::json::parse(text)) {
        if (r["name"].get<std::string>() != s.name) continue;
        s.simulated += r["simulated"].get<Index>();
        s.lr_seconds += r["lr_seconds"].get<double>();
        s.hr_seconds += r["hr_seconds"].get<double>();
        s.lr_iterations += r["lr_iterations"].get<Index>();
        s.hr_iterations += r["hr_iterations"].get<Index>();
        s.lead_in_frames += r["lead_in_frames"].get<Index>();
        s.lead_in_seconds += r["lead_in_seconds"].get<double>();
        all_reused = all_reused && r["reused"].get<bool>();
      }
    s.reused = s.simulated == 0 && all_reused;
  }
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
  scenario::FaceDatasetOptions run = o;
  run.chunks = scenario::face_dataset_chunks(o, parts, comm.size());  // the same on every rank
  const auto mine = scenario::simulate_face_dataset(policy, parts, run, out, log, comm.shard());
  return nlohmann::ordered_json::parse(finish_on_root(comm, detail::stats_json(mine).dump(), [&](const std::vector<std::string>& all) {
    auto stats = scenario::simulate_face_dataset(policy, parts, run, out, {});  // every unit is done: files reused, chunks assembled
    detail::add_rank_stats(stats, all);
    return scenario::finish_face_dataset(policy, parts, stats, run, out, log, {{"ranks", comm.size()}}).dump();
  }));
}

}  // namespace simsr::mpi
