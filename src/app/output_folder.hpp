// An output folder belongs to one run (README, "Exit codes and interrupted runs"): while a run
// writes into it, it holds an advisory lock (flock) on the folder's .seamless.lock, so a second
// run into the same folder stops before writing anything; a folder that holds an earlier run is
// refused unless --force, and --force removes only what seamless wrote there: the files listed in
// the earlier run's manifest.txt or, where there is none (a run killed outright), the names
// seamless writes. Inputs and unknown files are never removed (the log names what was kept), and
// an --out that is, or contains, one of the run's inputs is refused.
#pragma once
#include <set>
#include <string>
#include <vector>

namespace seamless::app {

// What seamless writes into a run folder (`seamless run`, track, reconstruct, simulate) or a
// recording (`seamless record`): --force removes these where an earlier run left no manifest.
bool written_by_seamless(const std::string& relative_path);

class OutputFolder {
 public:
  // Creates `dir` (a permission problem is named as such), takes its lock (UsageError when another
  // run holds it), refuses a folder that is or contains one of `inputs` (UsageError), and when it
  // holds an earlier run (one of `marks` is there) refuses it (UsageError) unless `force`, or the
  // earlier run failed before computing anything (summary.json says so): then the earlier run's
  // files are removed and the others kept, each kept one named in the log.
  OutputFolder(std::string dir, bool force, const std::vector<std::string>& inputs,
               const std::vector<std::string>& marks);
  ~OutputFolder();  // releases the lock
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  const std::string& dir() const { return dir_; }
  // Writes manifest.txt: every file below the folder that was not there when it was opened
  // (what this run wrote), for a later --force. Never throws (logs a failure).
  void write_manifest(const std::string& command) const noexcept;
  // Removes the *.partial files this run left (a writer that failed part way): they are never
  // complete, and on a full disk they keep it full. Never throws.
  void remove_partial_files() const noexcept;

 private:
  std::string dir_;
  int lock_fd_ = -1;
  std::set<std::string> before_;  // files (relative paths) present when opened, after any clearing
};

}  // namespace seamless::app
