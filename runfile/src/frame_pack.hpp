// The packed storage of a run's people (run files with run value
// frames = "packed"; issue 66): one row per frame of table
//   frame_pack(frame INTEGER PRIMARY KEY, key INTEGER, xmin, xmax, ymin, ymax REAL, data BLOB)
// holding, without loss, what tables trajectory_data, person_state and
// person_load hold of the frame in a run file of tables: every present
// person's index, position, velocity, angle, angular velocity, state, load
// and chest and lateral loads. The tables' values are the doubles the
// engine gave, so the pack keeps every bit of them (as SQLite stores them:
// -0 as 0), and a reader gives the same numbers from either storage.
//
// A frame's bytes (`data`): 'P', the version (1), flags (1 = key frame,
// 2 = with chest and lateral loads), the number of people as a varint, how
// many frames back the frame it continues is (0 for a key frame; a reader
// checks it, so that a missing row is found, never predicted from the wrong
// frame), then one zstd frame (with its checksum) of
//   the people's indices as gaps (index - previous index - 1) in varints,
//   their states, a byte each,
//   for each number of a person (x, y, angle, vx, vy, omega, load[, chest,
//   lateral]) the bits of the value XOR the bits of its prediction, as eight
//   byte planes (the most significant first: n bytes each).
// The prediction of a person's number is its value in the frame before
// (0 when the person was not in it); positions and the angle are
// extrapolated from the two frames before where the person was in both
// (x1 + (x1 - x0)). Predictions that are good leave planes of zeros, which
// zstd stores in a few bytes. A key frame predicts from nothing, so that
// reading can start there (every kKeyInterval-th frame, and the first frame
// a writer writes, e.g. after a resume).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "crowdrecon/runfile/run_file.hpp"

struct ZSTD_CCtx_s;
struct ZSTD_DCtx_s;
using ZSTD_CCtx = ZSTD_CCtx_s;
using ZSTD_DCtx = ZSTD_DCtx_s;

namespace crowdrecon::runfile::detail {

inline constexpr int kPackVersion = 1;

// A number as a REAL column of SQLite gives it back (-0 as 0): the pack
// stores numbers so, and a reader of packed frames gives them so.
inline double AsStored(double v) { return v == 0.0 ? 0.0 : v; }
// The direction the chest faces, as table trajectory_data holds it
// (ori_x, ori_y) for `angle`: every writer and reader of that table.
inline Vec2 OrientationOf(double angle) { return {AsStored(std::cos(angle)), AsStored(std::sin(angle))}; }
inline constexpr std::int64_t kKeyInterval = 64;  // frames

// The people of one frame as the pack holds them.
struct PackedPeople {
  std::vector<std::uint32_t> person;  // person indices, ascending
  std::vector<Vec2> position_m, velocity_m_per_s;
  std::vector<double> angle_rad, angular_velocity_rad_per_s, load_n;
  std::vector<PersonStatus> state;
  bool has_loads = false;             // chest_n and lateral_n hold every person's
  std::vector<double> chest_n, lateral_n;
};

// What a packer and an unpacker remember of the frames before: each
// person's last numbers, and in which frame of the sequence they were seen.
class PackHistory {
 public:
  static constexpr int kNumbers = 9;
  void Key() { seq_ += 2; }   // a key frame: nobody was in the frame before
  void Next() { seq_ += 1; }
  // The prediction of number c of person i in the current frame.
  double Predict(std::uint32_t i, int c) const;
  void Remember(std::uint32_t i, const double* numbers);

 private:
  struct Track {
    std::int64_t seen = -10, seen_before = -10;
    double value[kNumbers] = {};
    double before[3] = {};  // x, y and the angle of the frame before `value`'s
  };
  std::vector<Track> tracks_;
  std::int64_t seq_ = 0;
};

class FramePacker {
 public:
  FramePacker();
  // The bytes of frame `f`'s people (its chest and lateral loads where it
  // has them for every person), in the order of their indices. Two entries
  // of one person are the caller's bug (never in a snapshot).
  std::string Pack(const FrameSnapshot& f, bool key);

 private:
  PackHistory history_;
  std::string payload_;
  std::vector<std::size_t> order_;
  std::int64_t previous_frame_ = -1;
  std::unique_ptr<ZSTD_CCtx, std::size_t (*)(ZSTD_CCtx*)> cctx_;
};

class FrameUnpacker {
 public:
  FrameUnpacker();
  // `people` bounds the person indices (the run's table person); `where`
  // names the frame in messages ("RUN: table frame_pack, frame 12"). A
  // damaged frame is an InputError; the unpacker must then start again at a
  // key frame.
  void Unpack(std::int64_t frame, const unsigned char* data, std::size_t size, std::size_t people, PackedPeople* out,
              const std::string& where);

 private:
  PackHistory history_;
  bool started_ = false;  // a key frame was read (and nothing damaged since)
  std::int64_t previous_frame_ = -1;
  std::unique_ptr<ZSTD_DCtx, std::size_t (*)(ZSTD_DCtx*)> dctx_;
  std::string payload_;
};

}  // namespace crowdrecon::runfile::detail
