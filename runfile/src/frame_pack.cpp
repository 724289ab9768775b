// The packed storage of a run's people (frame_pack.hpp).
#include "frame_pack.hpp"

#include <zstd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <new>
#include <stdexcept>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::runfile::detail {

namespace {

constexpr unsigned char kMagic = 'P';
constexpr unsigned kKeyFlag = 1, kLoadsFlag = 2;
constexpr int kZstdLevel = 3;

void PutVarint(std::string& out, std::uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<char>((v & 0x7f) | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<char>(v));
}

// Reads a varint at `at`, advancing it; false if the bytes end first or it
// runs beyond 64 bits.
bool GetVarint(const unsigned char* data, std::size_t size, std::size_t& at, std::uint64_t& v) {
  v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    if (at >= size) return false;
    const unsigned char b = data[at++];
    v |= std::uint64_t{b & 0x7fu} << shift;
    if (!(b & 0x80)) return true;
  }
  return false;
}

}  // namespace

double PackHistory::Predict(std::uint32_t i, int c) const {
  if (i >= tracks_.size()) return 0.0;
  const Track& t = tracks_[i];
  if (t.seen != seq_ - 1) return 0.0;
  if (c < 3 && t.seen_before == seq_ - 2) return t.value[c] + (t.value[c] - t.before[c]);
  return t.value[c];
}

void PackHistory::Remember(std::uint32_t i, const double* numbers) {
  if (i >= tracks_.size()) tracks_.resize(static_cast<std::size_t>(i) + 1);
  Track& t = tracks_[i];
  for (int c = 0; c < 3; ++c) t.before[c] = t.value[c];
  t.seen_before = t.seen;
  t.seen = seq_;
  std::memcpy(t.value, numbers, sizeof t.value);
}

FramePacker::FramePacker() : cctx_(ZSTD_createCCtx(), &ZSTD_freeCCtx) {
  if (!cctx_) throw std::bad_alloc();
  ZSTD_CCtx_setParameter(cctx_.get(), ZSTD_c_compressionLevel, kZstdLevel);
  ZSTD_CCtx_setParameter(cctx_.get(), ZSTD_c_checksumFlag, 1);  // a damaged frame is found, not read
}

FrameUnpacker::FrameUnpacker() : dctx_(ZSTD_createDCtx(), &ZSTD_freeDCtx) {
  if (!dctx_) throw std::bad_alloc();
}

std::string FramePacker::Pack(const FrameSnapshot& f, bool key) {
  if (!key && !(f.frame > previous_frame_))
    throw std::logic_error("FramePacker: frame " + std::to_string(f.frame) + " after frame " + std::to_string(previous_frame_));
  const std::size_t n = f.person.size();
  const bool loads = f.chest_load_n.size() == n && f.lateral_load_n.size() == n;
  const int numbers = loads ? PackHistory::kNumbers : PackHistory::kNumbers - 2;
  if (key) history_.Key(); else history_.Next();
  payload_.clear();
  // By person index (a snapshot lists its people in the engine's order).
  order_.resize(n);
  for (std::size_t k = 0; k < n; ++k) order_[k] = k;
  if (!std::is_sorted(f.person.begin(), f.person.end()))
    std::sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return f.person[a] < f.person[b]; });
  std::int64_t previous = -1;
  for (const std::size_t k : order_) {
    PutVarint(payload_, static_cast<std::uint64_t>(static_cast<std::int64_t>(f.person[k]) - previous - 1));
    previous = f.person[k];
  }
  for (const std::size_t k : order_) payload_.push_back(static_cast<char>(f.state[k]));
  const std::size_t planes_at = payload_.size();
  payload_.resize(planes_at + static_cast<std::size_t>(numbers) * 8 * n);
  auto* planes = reinterpret_cast<unsigned char*>(payload_.data() + planes_at);
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t k = order_[j];
    const std::uint32_t i = f.person[k];
    const double v[PackHistory::kNumbers] = {
        AsStored(f.position_m[k].x), AsStored(f.position_m[k].y), AsStored(f.angle_rad[k]),
        AsStored(f.velocity_m_per_s[k].x), AsStored(f.velocity_m_per_s[k].y),
        AsStored(f.angular_velocity_rad_per_s[k]), AsStored(f.load_n[k]),
        loads ? AsStored(f.chest_load_n[k]) : 0.0, loads ? AsStored(f.lateral_load_n[k]) : 0.0};
    for (int c = 0; c < numbers; ++c) {
      const std::uint64_t r = std::bit_cast<std::uint64_t>(v[c]) ^ std::bit_cast<std::uint64_t>(history_.Predict(i, c));
      unsigned char* plane = planes + static_cast<std::size_t>(c) * 8 * n;
      for (int b = 0; b < 8; ++b) plane[static_cast<std::size_t>(b) * n + j] = static_cast<unsigned char>(r >> (56 - 8 * b));
    }
    history_.Remember(i, v);
  }
  std::string out;
  out.push_back(static_cast<char>(kMagic));
  out.push_back(static_cast<char>(kPackVersion));
  out.push_back(static_cast<char>((key ? kKeyFlag : 0u) | (loads ? kLoadsFlag : 0u)));
  PutVarint(out, n);
  PutVarint(out, key ? 0 : static_cast<std::uint64_t>(f.frame - previous_frame_));
  previous_frame_ = f.frame;
  const std::size_t header = out.size();
  out.resize(header + ZSTD_compressBound(payload_.size()));
  const std::size_t packed =
      ZSTD_compress2(cctx_.get(), out.data() + header, out.size() - header, payload_.data(), payload_.size());
  if (ZSTD_isError(packed)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(packed));
  out.resize(header + packed);
  return out;
}

void FrameUnpacker::Unpack(std::int64_t frame, const unsigned char* data, std::size_t size, std::size_t people,
                           PackedPeople* out, const std::string& where) {
  using namespace run_limits;
  const auto damaged = [&](const std::string& what) {
    history_ = PackHistory{};
    started_ = false;
    throw InputError(where + ": " + what + " (the run file is damaged)");
  };
  if (size < 4 || data[0] != kMagic) damaged("column data is not a packed frame (expected it to begin with 'P')");
  if (data[1] != kPackVersion)
    throw InputError(where + ": packed with version " + std::to_string(data[1]) + "; this crowdrecon reads version " +
                     std::to_string(kPackVersion) + " (a run file written by a newer crowdrecon?)");
  const unsigned flags = data[2];
  if (flags & ~(kKeyFlag | kLoadsFlag)) damaged("unknown flags " + std::to_string(flags));
  const bool key = flags & kKeyFlag;
  const bool loads = flags & kLoadsFlag;
  if (!key && !started_) damaged("a frame that continues one before it, read without it (expected a key frame first)");
  std::size_t at = 3;
  std::uint64_t n = 0;
  if (!GetVarint(data, size, at, n) || n > people)
    damaged("its number of people is not in [0, " + std::to_string(people) + "] (the people of table person)");
  std::uint64_t back = 0;
  if (!GetVarint(data, size, at, back)) damaged("its header is cut short");
  if (key != (back == 0) || (!key && (back > static_cast<std::uint64_t>(frame) ||
                                      frame - static_cast<std::int64_t>(back) != previous_frame_)))
    damaged("it continues frame " + std::to_string(frame - static_cast<std::int64_t>(back)) + ", but the frame read before it is " +
            std::to_string(previous_frame_) + " (a frame of table frame_pack is missing)");
  const int numbers = loads ? PackHistory::kNumbers : PackHistory::kNumbers - 2;
  const std::size_t planes = static_cast<std::size_t>(numbers) * 8 * n;
  // Gaps take 1 to 10 bytes each (a gap beyond the table's people is refused below).
  const unsigned long long content = ZSTD_getFrameContentSize(data + at, size - at);
  if (content == ZSTD_CONTENTSIZE_ERROR || content == ZSTD_CONTENTSIZE_UNKNOWN || content < 2 * n + planes ||
      content > 11 * n + planes)
    damaged("its compressed people are not a zstd frame of the size " + std::to_string(n) + " people take");
  payload_.resize(content);
  const std::size_t got = ZSTD_decompressDCtx(dctx_.get(), payload_.data(), payload_.size(), data + at, size - at);
  if (ZSTD_isError(got) || got != content) damaged("its compressed people do not decompress");
  const auto* p = reinterpret_cast<const unsigned char*>(payload_.data());
  std::size_t q = 0;
  out->person.resize(n);
  std::int64_t previous = -1;
  for (std::size_t k = 0; k < n; ++k) {
    std::uint64_t gap = 0;
    if (!GetVarint(p, content, q, gap) || gap >= people || previous + 1 + static_cast<std::int64_t>(gap) >= static_cast<std::int64_t>(people))
      damaged("person " + std::to_string(k) + " of the frame has an index beyond the " + std::to_string(people) +
              " people of table person");
    previous += 1 + static_cast<std::int64_t>(gap);
    out->person[k] = static_cast<std::uint32_t>(previous);
  }
  if (content - q != n + planes) damaged("its people's numbers do not fill the frame");
  out->state.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const unsigned char s = p[q + k];
    if (s > 2)
      damaged("person " + std::to_string(out->person[k] + 1) + ": state " + std::to_string(s) +
              "; expected 0 (walking), 1 (fallen) or 2 (removed)");
    out->state[k] = static_cast<PersonStatus>(s);
  }
  q += n;
  if (key) history_.Key(); else history_.Next();
  started_ = true;
  previous_frame_ = frame;
  out->has_loads = loads;
  out->position_m.resize(n);
  out->velocity_m_per_s.resize(n);
  out->angle_rad.resize(n);
  out->angular_velocity_rad_per_s.resize(n);
  out->load_n.resize(n);
  out->chest_n.assign(loads ? n : 0, 0.0);
  out->lateral_n.assign(loads ? n : 0, 0.0);
  static constexpr const char* kColumn[PackHistory::kNumbers] = {"pos_x", "pos_y", "angle_rad", "vel_x", "vel_y",
                                                                 "omega_rad_per_s", "load_n", "chest_n", "lateral_n"};
  static constexpr double kMin[PackHistory::kNumbers] = {-kCoordinate_m, -kCoordinate_m, -kAngle_rad, -kSpeed_m_per_s,
                                                         -kSpeed_m_per_s, -kAngularSpeed_rad_per_s, 0.0, 0.0, 0.0};
  static constexpr double kMax[PackHistory::kNumbers] = {kCoordinate_m, kCoordinate_m, kAngle_rad, kSpeed_m_per_s,
                                                         kSpeed_m_per_s, kAngularSpeed_rad_per_s, kForce_n, kForce_n,
                                                         kForce_n};
  const unsigned char* plane0 = p + q;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = out->person[k];
    double v[PackHistory::kNumbers] = {};
    for (int c = 0; c < numbers; ++c) {
      const unsigned char* plane = plane0 + static_cast<std::size_t>(c) * 8 * n;
      std::uint64_t r = 0;
      for (int b = 0; b < 8; ++b) r = (r << 8) | plane[static_cast<std::size_t>(b) * n + k];
      v[c] = std::bit_cast<double>(r ^ std::bit_cast<std::uint64_t>(history_.Predict(i, c)));
      if (!(v[c] >= kMin[c] && v[c] <= kMax[c]))
        damaged("person " + std::to_string(i + 1) + ", " + kColumn[c] + ": found " + FormatNumber(v[c]) +
                "; expected a number in [" + FormatNumber(kMin[c]) + ", " + FormatNumber(kMax[c]) + "]");
    }
    history_.Remember(i, v);
    out->position_m[k] = {v[0], v[1]};
    out->angle_rad[k] = v[2];
    out->velocity_m_per_s[k] = {v[3], v[4]};
    out->angular_velocity_rad_per_s[k] = v[5];
    out->load_n[k] = v[6];
    if (loads) {
      out->chest_n[k] = v[7];
      out->lateral_n[k] = v[8];
    }
  }
}

}  // namespace crowdrecon::runfile::detail
