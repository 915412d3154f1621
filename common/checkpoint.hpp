// Checkpoints of a run: every program's complete state after a committed step n, in
// OUT/checkpoint/step_<n>/<role>.h5. Each file is written under a temporary name, flushed to disk
// and renamed into place, so a crash while writing leaves the last good checkpoint intact. A step
// whose folder holds the file of every program the scene needs is complete; a restart takes the
// newest complete step (README.md, "Stopping and resuming").
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "h5.hpp"
#include "probes.hpp"
#include "runtime.hpp"

namespace fsi {

std::filesystem::path checkpoint_folder(const std::filesystem::path& out_dir, long step);
std::filesystem::path checkpoint_file(const std::filesystem::path& out_dir, long step, Role role);

// Write this program's checkpoint of step `step` (the state at t^step, after that step's output):
// `fill` writes the state into the file; the file also records the step, the time and the
// program's effective scene (checked at a restart). Then the folders of steps older than the
// program's previous checkpoint are cleared of this program's file (and removed when empty), so
// that the newest complete checkpoint is never lost. A program on several ranks (the fluid):
// its rank 0 writes the file, calling `fill`; the other ranks call `others` instead, which takes
// part in the same collective gathers without a file.
void write_checkpoint(const Runtime& rt, long step, const std::function<void(H5File&)>& fill,
                      const std::function<void()>& others = {});

// The newest step of out_dir/checkpoint whose folder holds a file of every role in `roles`.
std::optional<long> newest_checkpoint(const std::filesystem::path& out_dir, const RoleSet& roles);

// That `role`'s file of step `step` was written by a build of this protocol version (the
// attribute protocol_version, since version 8); an InputError naming both otherwise.
void check_checkpoint_version(const std::filesystem::path& out_dir, long step, Role role,
                              const std::filesystem::path& scene_file);

// A restarted program's checkpoint file, opened for reading, after checking that the scene's
// physics did not change: every key of the effective scene but time.t_end, [output],
// scene.description and [test] must be as it was, and a key set on one side only counts when
// this program reads it (changed_physics_key; an InputError names the first that changed).
H5File open_restart(const Runtime& rt);

// Output files that continue at a restart: created afresh in a new run; in a restarted one
// reopened with what they held up to the restart step (an .h5 file's step groups beyond it
// removed, a CSV file's rows after the restart time dropped), so that the time series continue
// without a lost or doubled row. The fields of the restart step itself stay only when it is an
// output step of the resumed scene (a run that ended there wrote them as its last).
// restart_fields_time(): the last field output time an XDMF side file keeps (XdmfWriter::resume).
H5File output_h5(const Runtime& rt, const std::filesystem::path& path);
ProbeCsv output_csv(const Runtime& rt, const std::filesystem::path& path, std::vector<std::string> columns);
// A list of vectors (per body, per fiber) in a checkpoint: NAME/values, all of them one after
// the other, and NAME/sizes.
void write_vectors(H5File& h5, const std::string& name, const std::vector<std::vector<double>>& v);
std::vector<std::vector<double>> read_vectors(const H5File& h5, const std::string& name);

// t of the restart step (0 in a new run).
double restart_time(const Runtime& rt);
double restart_fields_time(const Runtime& rt);

// The first key whose value differs between two effective scenes (TOML texts), outside the keys
// a restart may change (see open_restart); empty when there is none. With `reads`, a key that
// only one of the two has counts when reads(table, key) says this program reads it; `side`, when
// given, is set to 1 for a key only `before` has, 2 for one only `now` has, else 0.
using ReadsKey = std::function<bool(const std::string& table, const std::string& key)>;
std::string changed_physics_key(const std::string& before, const std::string& now,
                                const ReadsKey& reads = nullptr, int* side = nullptr);

}  // namespace fsi
