#include "app/output_folder.hpp"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>

#include "app/json_file.hpp"
#include "core/error.hpp"
#include "core/output_file.hpp"

namespace seamless::app {

namespace fs = std::filesystem;

namespace {

constexpr const char* kLock = ".seamless.lock";
constexpr const char* kManifest = "manifest.txt";

fs::path normal(const std::string& p) {
  std::error_code ec;
  fs::path a = fs::weakly_canonical(fs::absolute(p), ec);
  return ec ? fs::absolute(p).lexically_normal() : a;
}

// `inner` is `outer` or lies below it (component-wise, after resolving links).
bool within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

// Every file below `dir` (relative, '/'-separated), the lock left out.
std::set<std::string> list_files(const fs::path& dir) {
  std::set<std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (it->is_directory(ec)) continue;
    const std::string rel = fs::relative(it->path(), dir, ec).generic_string();
    if (!ec && rel != kLock) files.insert(rel);
  }
  return files;
}

std::string first_names(const std::vector<std::string>& names, std::size_t n = 8) {
  std::string s;
  for (std::size_t i = 0; i < names.size() && i < n; ++i) s += (i ? ", " : "") + names[i];
  if (names.size() > n) s += ", ... (" + std::to_string(names.size() - n) + " more)";
  return s;
}

// The earlier run failed before it computed a frame or a solver step (a problem found after
// start-up: intrinsics, particle budget, depth scale): its folder holds only its log, config and
// summary, and the corrected re-run may replace them without --force.
bool failed_before_computing(const fs::path& dir) {
  std::ifstream in(dir / "summary.json");
  if (!in) return false;
  const Json j = Json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("status", "") != "failed" || !j.contains("reached")) return false;
  const Json& r = j["reached"];
  return r.value("frames", -1) == 0 && r.value("steps", -1) == 0;
}

// Removes `rel` below `dir` (files only) and then its parent folders that became empty.
bool remove_file(const fs::path& dir, const std::string& rel) {
  const fs::path p = (dir / rel).lexically_normal();
  std::error_code ec;
  if (rel.empty() || fs::path(rel).is_absolute() || !within(p, dir.lexically_normal()) || fs::is_directory(p, ec))
    return false;  // a manifest line that points outside the folder is never followed
  if (!fs::remove(p, ec)) return false;
  for (fs::path d = p.parent_path(); d != dir && within(d, dir) && fs::is_empty(d, ec); d = d.parent_path())
    fs::remove(d, ec);
  return true;
}

// manifest.txt: the files a run wrote, one per line. Written at the start as "in progress", with
// the files that were there before ("! name": never removed), and complete at the end.
struct Manifest {
  bool found = false, complete = false;
  std::set<std::string> written, before;
};
constexpr const char* kInProgress = "# in progress";

Manifest read_manifest(const fs::path& dir) {
  Manifest m;
  std::ifstream in(dir / kManifest);
  m.found = static_cast<bool>(in);
  m.complete = m.found;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(kInProgress, 0) == 0) m.complete = false;
    else if (line.rfind("! ", 0) == 0) m.before.insert(line.substr(2));
    else if (!line.empty() && line[0] != '#') m.written.insert(line);
  }
  return m;
}

// What a recording holds (io/record.cpp): without a manifest, never taken for seamless's own,
// since a TUM folder from elsewhere has the same names.
bool recording_name(const std::string& rel) {
  static const std::regex names(
      R"(((rgb|depth|associations|calibration|movers|accelerometer|groundtruth)\.txt|(rgb|depth|mask)/.*)(\.partial)?)");
  return std::regex_match(rel, names);
}

}  // namespace

bool written_by_seamless(const std::string& rel) {
  // Run folders (app/, recon/tracker_sequence.cpp, recon/refine/, render/headless_output.cpp) and
  // recordings (io/record.cpp); their *.partial while being written; PNGs in the image folders.
  static const std::regex known(
      R"((config\.yaml|log\.txt|timings\.csv|summary\.json|manifest\.txt|trajectory(_odometry|_live)?\.txt|)"
      R"(groundtruth\.txt|intrinsics\.txt|tracking_stats\.csv|refine_stats\.csv|online_refine_stats\.csv|)"
      R"(mesh\.ply|scene_particles\.ply|particles(_[0-9]+)?\.ply|objects\.txt|preview\.png|video\.mp4|)"
      R"(rgb\.txt|depth\.txt|associations\.txt|calibration\.txt|movers\.txt|accelerometer\.txt|)"
      R"((frames|stages|dynamic_mask|render/frames|render/stages|rgb|depth|mask)/[^/]+\.png|render/video\.mp4)"
      R"()(\.partial)?)");
  return rel == kLock || std::regex_match(rel, known);
}

OutputFolder::OutputFolder(std::string dir, bool force, const std::vector<std::string>& inputs,
                           const std::vector<std::string>& marks)
    : dir_(std::move(dir)) {
  std::error_code ec;
  if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
    throw UsageError("the output folder " + dir_ + " is a file; give --out a folder");
  const fs::path out = normal(dir_);
  for (const std::string& in : inputs) {
    if (in.empty() || !fs::exists(in, ec)) continue;
    if (within(normal(in), out))
      throw UsageError("--out " + dir_ + (normal(in) == out ? " is" : " contains") + " the input " + in +
                       ": a run never writes over its input; choose another --out");
  }
  fs::create_directories(dir_, ec);
  if (ec == std::errc::permission_denied || ec == std::errc::operation_not_permitted ||
      ec == std::errc::read_only_file_system)
    throw UsageError("cannot create the output folder " + dir_ + ": " + ec.message() +
                     " (choose an --out you can write to)");
  if (ec) throw Error("cannot create the output folder " + dir_ + ": " + ec.message());
  if (access(dir_.c_str(), W_OK | X_OK) != 0)
    throw UsageError("the output folder " + dir_ + " is not writable: " + std::strerror(errno) +
                     " (choose an --out you can write to)");

  const std::string lock = (fs::path(dir_) / kLock).string();
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0) throw Error("cannot create the lock file " + lock + ": " + std::strerror(errno));
  if (flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    char pid[32] = {};
    const ssize_t n = pread(lock_fd_, pid, sizeof pid - 1, 0);
    ::close(lock_fd_);
    lock_fd_ = -1;
    std::string who = n > 0 ? std::string(pid, static_cast<std::size_t>(n)) : "";
    who.erase(std::remove(who.begin(), who.end(), '\n'), who.end());
    throw UsageError("another seamless run" + (who.empty() ? "" : " (process " + who + ")") + " is writing into " +
                     dir_ + "; wait for it to end, or choose another --out");
  }
  const std::string pid = std::to_string(getpid()) + "\n";
  if (ftruncate(lock_fd_, 0) != 0 || pwrite(lock_fd_, pid.data(), pid.size(), 0) < 0)
    spdlog::debug("could not write the process id into {}", lock);

  std::vector<std::string> found;
  for (const std::string& m : marks)
    if (fs::exists(fs::path(dir_) / m, ec)) found.push_back(m);
  if (!found.empty()) {
    const bool failed_empty = failed_before_computing(dir_);
    if (!force && !failed_empty) {
      ::close(lock_fd_);
      lock_fd_ = -1;
      throw UsageError("the output folder " + dir_ + " holds an earlier run (" + first_names(found) +
                       "); choose another --out, or add --force to remove that run's files first");
    }
    // Plan first, remove after: a folder whose marks would survive (a file seamless cannot tell
    // for its own) is refused with nothing removed, and never written over.
    const Manifest m = read_manifest(dir_);
    std::vector<std::string> remove, kept;
    for (const std::string& rel : list_files(dir_)) {
      const bool infrastructure = rel == kManifest || rel == partial_path(kManifest) || rel == "summary.json.partial";
      bool ours = infrastructure;
      if (m.complete)
        ours = ours || m.written.count(rel) || (rel.size() > 8 && m.written.count(rel.substr(0, rel.size() - 8)));
      else if (m.found) ours = ours || (written_by_seamless(rel) && !m.before.count(rel));  // killed part way
      else ours = ours || (written_by_seamless(rel) && !recording_name(rel));
      (ours ? remove : kept).push_back(rel);
    }
    std::vector<std::string> blocking;
    for (const std::string& mark : found)
      if (std::find(kept.begin(), kept.end(), mark) != kept.end()) blocking.push_back(mark);
    if (!blocking.empty()) {
      ::close(lock_fd_);
      lock_fd_ = -1;
      throw UsageError("the output folder " + dir_ + " holds " + first_names(blocking) +
                       ", which no manifest.txt of seamless lists as its own (another tool's data, or a "
                       "recording from before seamless wrote manifests): --force removes only what seamless "
                       "wrote; move it away or choose another --out");
    }
    std::size_t removed = 0;
    for (const std::string& rel : remove) removed += remove_file(dir_, rel);
    const char* why = failed_empty ? "the earlier run failed before computing anything" : "--force";
    spdlog::info("{}: removed {} files of the earlier run from {} ({})", why, removed, dir_,
                 m.complete ? "those its manifest.txt lists"
                 : m.found  ? "it was stopped part way: the names seamless writes"
                            : "it left no manifest: the names seamless writes");
    if (!kept.empty())
      spdlog::warn("{}: kept {} files in {} that seamless did not write there: {}", why, kept.size(), dir_,
                   first_names(kept));
  }
  before_ = list_files(dir_);
  // The manifest of a run in progress: a run killed outright leaves it so, with the files that
  // were here before it, which a later --force keeps.
  std::ofstream start(fs::path(dir_) / kManifest);
  start << kInProgress << ": a seamless run writes into this folder (or was stopped before its end)\n";
  for (const std::string& rel : before_)
    if (rel != kManifest) start << "! " << rel << "\n";
  if (!start) spdlog::warn("cannot write {}/{}", dir_, kManifest);
}

OutputFolder::~OutputFolder() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock
}

void OutputFolder::write_manifest(const std::string& command) const noexcept {
  try {
    const fs::path path = fs::path(dir_) / kManifest;
    std::ofstream out(partial_path(path.string()));
    out << "# files written by `seamless " << command << "` into this folder (--force removes these, and only these)\n";
    for (const std::string& rel : list_files(dir_))
      if (!before_.count(rel) && rel != kManifest && rel != partial_path(kManifest)) out << rel << "\n";
    for (const std::string& rel : before_)
      if (rel != kManifest) out << "! " << rel << "\n";  // there before the run: never removed
    out.close();
    if (!out) throw Error("cannot write " + path.string());
    commit_partial(path.string());
  } catch (const std::exception& e) {
    spdlog::error("manifest: {}", e.what());
  }
}

void OutputFolder::remove_partial_files() const noexcept {
  try {
    std::vector<std::string> removed;
    for (const std::string& rel : list_files(dir_)) {
      const std::string suffix = ".partial";
      if (before_.count(rel) || rel.size() <= suffix.size() ||
          rel.compare(rel.size() - suffix.size(), suffix.size(), suffix) != 0)
        continue;
      if (remove_file(dir_, rel)) removed.push_back(rel);
    }
    if (!removed.empty())
      spdlog::warn("removed {} incomplete files (a writer failed part way): {}", removed.size(), first_names(removed));
  } catch (const std::exception& e) {
    spdlog::error("removing incomplete files: {}", e.what());
  }
}

}  // namespace seamless::app
