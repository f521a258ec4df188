#pragma once
/// \file
/// SoftDECA's sampled data over MPI ranks (`mpirun -np R simsr datagen --scenario softdeca`):
/// rank r simulates shard r of R, a contiguous block of the samples
/// (scenario::SoftDecaDatagenOptions::shard), each sample written to its own file atomically as
/// the single-process run writes it; once every rank is done, rank 0 assembles the data set's
/// files from them (softdeca_samples.npz, softdeca_data.json) with the single-process code, which
/// finds every sample's file. The samples are independent (each drawn from the seed and its
/// index), so the assembled files equal the single-process run's bitwise, the wall-clock
/// `seconds` aside. A killed rank loses only the sample it was simulating; a rerun (any number of
/// ranks) resumes from the files. The summary adds `ranks` and each rank's part, and counts
/// `simulated` / `resumed` over the ranks.
///
///     auto report = mpi::generate_softdeca_dataset(exec::omp, comm, tpl, "ict", options, "out/softdeca");

#include <filesystem>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "../io/atomic_file.hpp"
#include "../scenario/softdeca/softdeca_datagen.hpp"
#include "communicator.hpp"

namespace simsr::mpi {

/// The data set of `o` (its `shard` must be the whole run: the ranks are the shards), every rank
/// taking part; every rank returns the whole run's summary (rank 0's). `say` gets each rank's
/// progress lines (prefix them with the rank to tell them apart).
template <class Simulator = scenario::SoftDecaSimulator, exec::HostPolicy P>
nlohmann::ordered_json generate_softdeca_dataset(P policy, const Communicator& comm, const scenario::SoftDecaTemplate& tpl, const std::string& name,
                                                 const scenario::SoftDecaDatagenOptions& o, const std::filesystem::path& dir,
                                                 const std::function<void(const std::string&)>& say = {}) {
  if (!o.shard.whole()) throw ArgumentError("mpi::generate_softdeca_dataset: the options name a shard already (the ranks are the shards)");
  if (comm.size() == 1) return scenario::generate_softdeca_dataset<Simulator>(policy, tpl, name, o, dir, say);
  scenario::SoftDecaDatagenOptions mine = o;
  mine.shard = comm.shard();
  const nlohmann::ordered_json part = scenario::generate_softdeca_dataset<Simulator>(policy, tpl, name, mine, dir, say);
  return nlohmann::ordered_json::parse(finish_on_root(comm, part.dump(), [&](const std::vector<std::string>& parts) {
    nlohmann::ordered_json j = scenario::generate_softdeca_dataset<Simulator>(policy, tpl, name, o, dir, {});  // every sample's file is there
    Index simulated = 0, resumed = 0;
    double seconds = 0;
    nlohmann::ordered_json per_rank = nlohmann::ordered_json::array(), per_sample = nlohmann::ordered_json::array();
    for (const auto& text : parts) {
      nlohmann::ordered_json p = nlohmann::ordered_json::parse(text);
      simulated += p["simulated"].get<Index>();
      resumed += p["resumed"].get<Index>();
      seconds += p["seconds_simulating"].get<double>();
      for (const auto& s : p["per_sample"]) per_sample.push_back(s);
      p.erase("per_sample");
      per_rank.push_back(std::move(p));
    }
    j["simulated"] = simulated;
    j["resumed"] = resumed;
    j["seconds_simulating"] = seconds;
    j["ranks"] = comm.size();
    j["per_rank"] = per_rank;
    j["per_sample"] = per_sample;
    io::write_file_atomic(dir / "softdeca_data.json", j.dump(2) + "\n");  // the whole run's summary, with the ranks' counts
    return j.dump();
  }));
}

}  // namespace simsr::mpi
