// The force computation of person pairs on a CUDA device: see cuda_collide.hpp
// for what it computes and why its results are the processor's, bit for bit.
//
// One thread per pair of the neighbour list, in two passes over the list:
// CountContacts runs the narrow phase and counts each pair's contact points;
// an exclusive prefix sum of the counts gives each pair's place in the
// contact list; WriteContacts runs the narrow phase again, writes the points
// there, and applies the contact law to them (the pair's overlap shares, its
// damping rates, each point's tangential spring from the previous
// evaluation's contact of the same pair and vertex, found by binary search).
// Running the narrow phase twice costs less than keeping a slot for every
// vertex of every pair between the passes.
#include "cuda_collide.hpp"

#include <cuda_runtime.h>

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "crowdrecon/common/error.hpp"
#include "minimum_image.hpp"
#include "narrow_phase_core.hpp"

namespace crowdrecon::engine::cuda {

namespace {

void Check(cudaError_t status, const char* what) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string("CUDA force computation: ") + what + ": " + cudaGetErrorString(status));
}

// A device buffer that grows (never shrinks) to what is asked of it.
template <typename T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  ~DeviceBuffer() {
    if (data_) cudaFree(data_);
  }
  void Reserve(std::size_t count) {
    if (count <= capacity_) return;
    if (data_) Check(cudaFree(data_), "cudaFree");
    data_ = nullptr;
    const std::size_t grown = std::max(count, capacity_ + capacity_ / 2);
    Check(cudaMalloc(&data_, grown * sizeof(T)), "cudaMalloc");
    capacity_ = grown;
  }
  void Upload(const T* host, std::size_t count, cudaStream_t stream) {
    Reserve(count);
    size_ = count;
    if (count > 0) Check(cudaMemcpyAsync(data_, host, count * sizeof(T), cudaMemcpyHostToDevice, stream), "upload");
  }
  T* data() { return data_; }
  const T* data() const { return data_; }
  std::size_t size() const { return size_; }
  void set_size(std::size_t count) {
    Reserve(count);
    size_ = count;
  }
  void swap(DeviceBuffer& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    std::swap(capacity_, other.capacity_);
  }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0, capacity_ = 0;
};

// Page-locked host memory that grows (never shrinks): copies between it and
// the device run at the bus's speed, several times faster than from ordinary
// (pageable) memory, which the driver first copies into a buffer of its own.
class PinnedBuffer {
 public:
  PinnedBuffer() = default;
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;
  ~PinnedBuffer() {
    if (data_) cudaFreeHost(data_);
  }
  unsigned char* Reserve(std::size_t bytes) {
    if (bytes > capacity_) {
      if (data_) Check(cudaFreeHost(data_), "cudaFreeHost");
      data_ = nullptr;
      const std::size_t grown = std::max(bytes, capacity_ + capacity_ / 2);
      Check(cudaMallocHost(&data_, grown), "cudaMallocHost");
      capacity_ = grown;
    }
    return data_;
  }

 private:
  unsigned char* data_ = nullptr;
  std::size_t capacity_ = 0;
};

// Several host arrays sent in one copy: each is copied into a page-locked
// staging buffer at an aligned offset (fast, in cache), then the whole
// buffer goes to the device at once, and each device array is a view into it.
class Upload {
 public:
  // Bytes of staging needed for arrays of these sizes (in bytes).
  static std::size_t Aligned(std::size_t bytes) { return (bytes + 255) / 256 * 256; }

  Upload(PinnedBuffer& host, DeviceBuffer<unsigned char>& device, std::size_t total_bytes)
      : host_(host.Reserve(total_bytes)), device_(device) {
    device_.set_size(total_bytes);
  }
  template <typename T>
  const T* Add(const T* data, std::size_t count) {
    const std::size_t bytes = count * sizeof(T);
    if (bytes > 0) std::memcpy(host_ + used_, data, bytes);
    const T* view = reinterpret_cast<const T*>(device_.data() + used_);
    used_ += Aligned(bytes);
    return view;
  }
  void Send(cudaStream_t stream) {
    if (used_ > 0) Check(cudaMemcpyAsync(device_.data(), host_, used_, cudaMemcpyHostToDevice, stream), "upload");
  }

 private:
  unsigned char* host_;
  DeviceBuffer<unsigned char>& device_;
  std::size_t used_ = 0;
};

// ShapeGeometry (narrow_phase.hpp) on the device: the same arrays, as
// pointers into one pool per kind.
struct DeviceGeometry {
  const Vec2* vertices = nullptr;
  const CoreEdge* edges = nullptr;
  const std::uint8_t* reflex = nullptr;
  std::uint32_t vertex_total = 0, edge_total = 0;
  __host__ __device__ std::uint32_t count() const { return vertex_total; }
  __host__ __device__ std::uint32_t edge_count() const { return edge_total; }
  bool closed = true;
  double radius_m = 0.0, core_radius_m = 0.0;
  Vec2 box_min, box_max;
  bool grid = false;
  double grid_reach_m = 0.0;
  Vec2 grid_origin;
  double grid_cell_m = 0.0;
  std::uint32_t grid_nx = 0, grid_ny = 0;
  const std::uint32_t* cell_start = nullptr;
  const std::uint16_t* cell_edges = nullptr;
};

struct Placed {
  const DeviceGeometry* geometry;
  Vec2 position;
  double cos_angle, sin_angle, scale;
};

struct Box {
  bool x = false, y = false;
  double lx = 0.0, ly = 0.0;
};

struct Bodies {
  const Vec2* position;
  const double* cos_angle;
  const double* sin_angle;
  const Vec2* velocity;
  const double* angular_velocity;
  const PersonState* state;
  const double* mass;
  const std::uint32_t* shape;
  const std::uint32_t* shape_family;
  const double* shape_scale;
  const DeviceGeometry* families;
};

// The previous evaluation's contacts, sorted by (pair key, feature).
struct History {
  const Contact* contacts;
  std::size_t count;
};

using detail::BoxesGap;
using detail::Closest;
using detail::ClosestOnCore;

// VerticesAgainst of narrow_phase.cpp, every vertex measured (no memory):
// calls sink(point, normal, overlap, feature) for each contact, in vertex order.
template <typename Sink>
__device__ void VerticesAgainst(const Placed& from, const Placed& to, bool flip, std::uint32_t tag, Sink& sink) {
  const DeviceGeometry& f = *from.geometry;
  const DeviceGeometry& g = *to.geometry;
  const detail::VertexFrame frame = detail::FrameOf(from, to);  // g's units and frame
  const double reach = frame.reach, unit = frame.unit, reach_g = frame.reach_g, c = frame.c, s = frame.s;
  const Vec2 o = frame.o, lo = frame.lo, hi = frame.hi;
  const bool use_grid = g.grid && reach_g <= g.grid_reach_m;
  const double inverse_cell = use_grid ? 1.0 / g.grid_cell_m : 0.0;
  for (std::uint32_t i = 0; i < f.count(); ++i) {
    const Vec2 v = f.vertices[i];
    const Vec2 p{c * v.x - s * v.y + o.x, s * v.x + c * v.y + o.y};
    if (p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y) continue;
    Closest cl;
    if (use_grid) {
      const double fx = (p.x - g.grid_origin.x) * inverse_cell, fy = (p.y - g.grid_origin.y) * inverse_cell;
      const std::uint32_t cx = fx <= 0.0 ? 0 : min(g.grid_nx - 1, static_cast<std::uint32_t>(fx));
      const std::uint32_t cy = fy <= 0.0 ? 0 : min(g.grid_ny - 1, static_cast<std::uint32_t>(fy));
      const std::uint32_t cell = cy * g.grid_nx + cx;
      const std::uint32_t first = g.cell_start[cell], last = g.cell_start[cell + 1];
      if (first == last) continue;
      cl = ClosestOnCore(p, g, g.cell_edges + first, last - first);
    } else {
      cl = ClosestOnCore(p, g, nullptr, g.edge_count());
    }
    if (cl.distance >= reach_g) continue;
    Vec2 normal;
    if (cl.distance > 0.0) {
      normal = (p - cl.point) / cl.distance;
    } else if (cl.distance < 0.0) {
      normal = (cl.point - p) / -cl.distance;
    } else {
      continue;
    }
    const double overlap = reach - cl.distance * unit;
    if (!(overlap > 0.0)) continue;
    const Vec2 local = cl.point * unit + normal * (g.radius_m * unit - overlap / 2.0);
    const Vec2 point = to.position + Vec2{to.cos_angle * local.x - to.sin_angle * local.y,
                                          to.sin_angle * local.x + to.cos_angle * local.y};
    const Vec2 world_normal{to.cos_angle * normal.x - to.sin_angle * normal.y,
                            to.sin_angle * normal.x + to.cos_angle * normal.y};
    sink(point, flip ? -world_normal : world_normal, overlap, tag | i);
  }
}

// CollideShapes of narrow_phase.cpp (contacts only).
template <typename Sink>
__device__ void CollideShapes(const Placed& a, const Placed& b, Sink& sink) {
  const DeviceGeometry& ga = *a.geometry;
  const DeviceGeometry& gb = *b.geometry;
  const double reach = ga.radius_m * a.scale + gb.radius_m * b.scale;
  const double bound = ga.core_radius_m * a.scale + gb.core_radius_m * b.scale + reach;
  const double d2 = LengthSquared(a.position - b.position);
  if (d2 >= bound * bound) return;
  if (BoxesGap(a, b, reach) > 0.0) return;
  const bool a_side = ga.count() == 1 || gb.count() != 1;
  const bool b_side = ga.count() != 1;
  if (a_side) VerticesAgainst(a, b, false, 0u, sink);
  if (b_side) VerticesAgainst(b, a, true, kVertexOfB, sink);
}

// Simulation::Separation.
__device__ Vec2 Separation(Vec2 a, Vec2 b, const Box& box) {
  Vec2 d = a - b;
  if (box.x) d.x = detail::MinimumImage(d.x, box.lx);
  if (box.y) d.y = detail::MinimumImage(d.y, box.ly);
  return d;
}

__device__ Placed PlaceBody(const Bodies& bodies, std::uint32_t i, Vec2 position) {
  const std::uint32_t shape = bodies.shape[i];
  return Placed{bodies.families + bodies.shape_family[shape], position, bodies.cos_angle[i], bodies.sin_angle[i],
                bodies.shape_scale[shape]};
}

// The pair's two placed shapes (b in a's periodic image), or false if one
// of the two has left.
__device__ bool PlacePair(const Bodies& bodies, const Box& box, std::uint32_t a, std::uint32_t b, Placed& pa,
                          Placed& pb) {
  if (bodies.state[a] == PersonState::kRemoved || bodies.state[b] == PersonState::kRemoved) return false;
  const Vec2 xa = bodies.position[a];
  const Vec2 xb_image = xa - Separation(xa, bodies.position[b], box);
  pa = PlaceBody(bodies, a, xa);
  pb = PlaceBody(bodies, b, xb_image);
  return true;
}

__global__ void CountContacts(Bodies bodies, Box box, const std::pair<std::uint32_t, std::uint32_t>* pairs,
                              std::size_t pair_count, std::uint32_t* counts) {
  const std::size_t k = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
  if (k > pair_count) return;
  std::uint32_t count = 0;
  Placed pa, pb;
  if (k < pair_count && PlacePair(bodies, box, pairs[k].first, pairs[k].second, pa, pb)) {
    auto sink = [&](Vec2, Vec2, double, std::uint32_t) { ++count; };
    CollideShapes(pa, pb, sink);
  }
  counts[k] = count;  // counts[pair_count] = 0: the prefix sum's last entry is the total
}

// The previous contact with this key and feature, as ContactHistory.
__device__ detail::ContactHistory FindHistory(const History& history, std::uint64_t key, std::uint32_t feature) {
  std::size_t lo = 0, hi = history.count;
  while (lo < hi) {  // first contact not before (key, feature)
    const std::size_t mid = lo + (hi - lo) / 2;
    const Contact& c = history.contacts[mid];
    const std::uint64_t ck = PairKey(c);
    if (ck < key || (ck == key && c.feature < feature))
      lo = mid + 1;
    else
      hi = mid;
  }
  detail::ContactHistory h;
  if (lo < history.count) {
    const Contact& c = history.contacts[lo];
    if (PairKey(c) == key && c.feature == feature) {
      h.exists = true;
      h.tangential_spring_m = c.tangential_spring_m;
      h.leading_fraction = c.leading_fraction;
    }
  }
  return h;
}

__global__ void WriteContacts(Bodies bodies, Box box, const std::pair<std::uint32_t, std::uint32_t>* pairs,
                              std::size_t pair_count, const std::uint32_t* offsets, detail::ContactLaw law,
                              History history, Contact* out, int* overlap_beyond) {
  const std::size_t k = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x;
  if (k >= pair_count) return;
  const std::uint32_t first = offsets[k], last = offsets[k + 1];
  if (first == last) return;
  const std::uint32_t a = pairs[k].first, b = pairs[k].second;
  Placed pa, pb;
  PlacePair(bodies, box, a, b, pa, pb);
  std::uint32_t next = first;
  auto sink = [&](Vec2 point, Vec2 normal, double overlap, std::uint32_t feature) {
    Contact& c = out[next++];
    c.a = a;
    c.b = b;
    c.wall = false;
    c.feature = feature;
    c.point_m = point;
    c.normal = normal;
    c.overlap_m = overlap;
  };
  CollideShapes(pa, pb, sink);
  // The contact law (Simulation::Collide's add_contacts): overlap shares,
  // damping rates once per pair, then each point.
  double sum = 0.0, sum2 = 0.0;
  for (std::uint32_t q = first; q < last; ++q) {
    sum += out[q].overlap_m;
    sum2 += out[q].overlap_m * out[q].overlap_m;
  }
  const double k_eff = sum * sum / sum2;
  const bool fa = bodies.state[a] != PersonState::kWalking, fb = bodies.state[b] != PersonState::kWalking;
  const double ma = bodies.mass[a], mb = bodies.mass[b];
  const double mass = fa && fb ? 0.5 * (ma + mb) : (fa ? mb : (fb ? ma : ma * mb / (ma + mb)));  // eq. (14)
  const detail::ContactLaw::Rates rates = law.PairRates(mass, k_eff);
  const double radii = pa.scale + pb.scale;  // (family radius 1)
  const std::uint64_t key = PairKey(false, a, b);
  bool beyond = false;
  for (std::uint32_t q = first; q < last; ++q) {
    Contact& c = out[q];
    const Vec2 va = fa ? Vec2{} : bodies.velocity[a] + Perp(c.point_m - pa.position) * bodies.angular_velocity[a];
    const Vec2 vb = fb ? Vec2{} : bodies.velocity[b] + Perp(c.point_m - pb.position) * bodies.angular_velocity[b];
    law.Apply(c, va - vb, mass, FindHistory(history, key, c.feature), c.overlap_m / sum, rates);
    beyond = beyond || !(c.overlap_m <= radii);
  }
  if (beyond) atomicOr(overlap_beyond, 1);
}

// Two entries per contact k, (a, k) and (b, k): sorted stably by body, they
// list each body's contacts in contact order.
__global__ void ListBodyContacts(const Contact* contacts, std::uint32_t count, std::uint32_t* bodies,
                                 std::uint32_t* indices) {
  const std::uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= count) return;
  bodies[2 * k] = contacts[k].a;
  indices[2 * k] = k;
  bodies[2 * k + 1] = contacts[k].b;
  indices[2 * k + 1] = k;
}

// Body i's sums over its contacts, in contact order (Simulation::Gather).
__global__ void SumPerBody(const Contact* contacts, const std::uint32_t* bodies, const std::uint32_t* indices,
                           std::uint32_t entries, const Vec2* position, Box box, std::uint32_t n,
                           detail::BodySums* sums) {
  const std::uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  std::uint32_t lo = 0, hi = entries;
  while (lo < hi) {  // first entry of body i or after
    const std::uint32_t mid = lo + (hi - lo) / 2;
    if (bodies[mid] < i)
      lo = mid + 1;
    else
      hi = mid;
  }
  detail::BodySums s;
  for (std::uint32_t e = lo; e < entries && bodies[e] == i; ++e) {
    const Contact& c = contacts[indices[e]];
    const Vec2 xa = position[c.a];
    if (c.a == i)
      detail::AddContact(s, c, true, xa);
    else
      detail::AddContact(s, c, false, xa - Separation(xa, position[c.b], box));
  }
  sums[i] = s;
}

}  // namespace

bool Available(std::string* why) {
  int devices = 0;
  const cudaError_t status = cudaGetDeviceCount(&devices);
  if (status != cudaSuccess || devices == 0) {
    if (why)
      *why = status != cudaSuccess ? std::string("no CUDA device: ") + cudaGetErrorString(status)
                                   : std::string("no CUDA device");
    return false;
  }
  return true;
}

struct Collider::Impl {
  cudaStream_t stream = nullptr;
  cudaEvent_t events[4] = {};
  Box box;
  // Geometry pools and the families that point into them.
  DeviceBuffer<Vec2> vertices;
  DeviceBuffer<CoreEdge> edges;
  DeviceBuffer<std::uint8_t> reflex;
  DeviceBuffer<std::uint32_t> cell_start;
  DeviceBuffer<std::uint16_t> cell_edges;
  DeviceBuffer<DeviceGeometry> families;
  DeviceBuffer<std::uint32_t> shape_family;
  DeviceBuffer<double> shape_scale;
  // Bodies: what changes at every step, in one copy through page-locked
  // staging; masses and shapes, which never change, once.
  PinnedBuffer upload_stage, download_stage;
  DeviceBuffer<unsigned char> bodies;
  DeviceBuffer<double> mass;
  DeviceBuffer<std::uint32_t> shape;
  std::size_t constant_bodies = 0;  // how many bodies' masses and shapes were sent
  // Pairs, counts and offsets, scan workspace.
  DeviceBuffer<std::pair<std::uint32_t, std::uint32_t>> pairs;
  std::uint64_t pair_generation = ~std::uint64_t{0};  // of the list on the device (none yet)
  DeviceBuffer<std::uint32_t> counts, offsets;
  DeviceBuffer<unsigned char> scan_workspace;
  // This evaluation's contacts and the previous one's.
  DeviceBuffer<Contact> contacts, previous;
  DeviceBuffer<int> flag;
  // Each body's contacts (stable sort by body) and its sums.
  DeviceBuffer<std::uint32_t> entry_body, entry_index, sorted_body, sorted_index;
  DeviceBuffer<unsigned char> sort_workspace;
  DeviceBuffer<detail::BodySums> sums;
  PinnedBuffer sums_stage;
  Timing timing;
  // Fault injection for tests (CROWDRECON_CUDA_FAIL_AFTER, cuda_collide.hpp).
  long fail_after = -1;
  long calls = 0;
};

Collider::Collider(const std::vector<ShapeGeometry>& families, const std::vector<std::uint32_t>& shape_family,
                   const std::vector<double>& shape_scale, const PeriodicBox& periodic)
    : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!Available(&why)) throw InputError("device: \"cuda\": " + why);
  Impl& m = *impl_;
  if (const char* fail = std::getenv("CROWDRECON_CUDA_FAIL_AFTER")) m.fail_after = std::atol(fail);
  Check(cudaStreamCreateWithFlags(&m.stream, cudaStreamNonBlocking), "cudaStreamCreate");
  for (cudaEvent_t& e : m.events) Check(cudaEventCreate(&e), "cudaEventCreate");
  m.box.x = periodic.x;
  m.box.y = periodic.y;
  m.box.lx = periodic.max_m.x - periodic.min_m.x;
  m.box.ly = periodic.max_m.y - periodic.min_m.y;
  // Pools first (their device addresses are final once uploaded), then the
  // families that point into them.
  std::vector<Vec2> all_vertices;
  std::vector<CoreEdge> all_edges;
  std::vector<std::uint8_t> all_reflex;
  std::vector<std::uint32_t> all_cell_start;
  std::vector<std::uint16_t> all_cell_edges;
  struct Offsets {
    std::size_t vertices, edges, reflex, cell_start, cell_edges;
  };
  std::vector<Offsets> at;
  for (const ShapeGeometry& g : families) {
    at.push_back({all_vertices.size(), all_edges.size(), all_reflex.size(), all_cell_start.size(), all_cell_edges.size()});
    all_vertices.insert(all_vertices.end(), g.vertices.begin(), g.vertices.end());
    all_edges.insert(all_edges.end(), g.edges.begin(), g.edges.end());
    all_reflex.insert(all_reflex.end(), g.reflex.begin(), g.reflex.end());
    all_cell_start.insert(all_cell_start.end(), g.cell_start.begin(), g.cell_start.end());
    all_cell_edges.insert(all_cell_edges.end(), g.cell_edges.begin(), g.cell_edges.end());
  }
  m.vertices.Upload(all_vertices.data(), all_vertices.size(), m.stream);
  m.edges.Upload(all_edges.data(), all_edges.size(), m.stream);
  m.reflex.Upload(all_reflex.data(), all_reflex.size(), m.stream);
  m.cell_start.Upload(all_cell_start.data(), all_cell_start.size(), m.stream);
  m.cell_edges.Upload(all_cell_edges.data(), all_cell_edges.size(), m.stream);
  std::vector<DeviceGeometry> device_families;
  for (std::size_t k = 0; k < families.size(); ++k) {
    const ShapeGeometry& g = families[k];
    DeviceGeometry d;
    d.vertices = m.vertices.data() + at[k].vertices;
    d.edges = m.edges.data() + at[k].edges;
    d.reflex = m.reflex.data() + at[k].reflex;
    d.vertex_total = g.count();
    d.edge_total = g.edge_count();
    d.closed = g.closed;
    d.radius_m = g.radius_m;
    d.core_radius_m = g.core_radius_m;
    d.box_min = g.box_min;
    d.box_max = g.box_max;
    d.grid = !g.cell_start.empty();
    d.grid_reach_m = g.grid_reach_m;
    d.grid_origin = g.grid_origin;
    d.grid_cell_m = g.grid_cell_m;
    d.grid_nx = g.grid_nx;
    d.grid_ny = g.grid_ny;
    d.cell_start = m.cell_start.data() + at[k].cell_start;
    d.cell_edges = m.cell_edges.data() + at[k].cell_edges;
    device_families.push_back(d);
  }
  m.families.Upload(device_families.data(), device_families.size(), m.stream);
  m.shape_family.Upload(shape_family.data(), shape_family.size(), m.stream);
  m.shape_scale.Upload(shape_scale.data(), shape_scale.size(), m.stream);
  m.flag.set_size(1);
  Check(cudaStreamSynchronize(m.stream), "geometry upload");
}

Collider::~Collider() {
  if (!impl_) return;
  for (cudaEvent_t e : impl_->events)
    if (e) cudaEventDestroy(e);
  if (impl_->stream) cudaStreamDestroy(impl_->stream);
}

Collider::Timing Collider::last_timing() const { return impl_->timing; }

bool Collider::Collide(const CollideInput& in, std::vector<Contact>& out, std::vector<detail::BodySums>& body_sums) {
  Impl& m = *impl_;
  if (m.fail_after >= 0 && m.calls++ >= m.fail_after)
    throw std::runtime_error("CUDA force computation: failure injected by CROWDRECON_CUDA_FAIL_AFTER");
  cudaStream_t stream = m.stream;
  Check(cudaEventRecord(m.events[0], stream), "cudaEventRecord");
  const std::size_t n = in.n;
  if (m.constant_bodies != n) {
    m.mass.Upload(in.mass_kg, n, stream);
    m.shape.Upload(in.shape, n, stream);
    m.constant_bodies = n;
  }
  const auto bytes = [&](std::size_t size) { return Upload::Aligned(n * size); };
  Upload upload(m.upload_stage, m.bodies,
                2 * bytes(sizeof(Vec2)) + 3 * bytes(sizeof(double)) + bytes(sizeof(PersonState)));
  const Vec2* position = upload.Add(in.position_m, n);
  const double* cos_angle = upload.Add(in.cos_angle, n);
  const double* sin_angle = upload.Add(in.sin_angle, n);
  const Vec2* velocity = upload.Add(in.velocity_m_per_s, n);
  const double* angular_velocity = upload.Add(in.angular_velocity_rad_per_s, n);
  const PersonState* state = upload.Add(in.state, n);
  upload.Send(stream);
  if (in.pair_generation != m.pair_generation) {
    m.pairs.Upload(in.pairs, in.pair_count, stream);
    m.pair_generation = in.pair_generation;
  }
  // The previous contacts: the device's own last output, or the caller's.
  if (!in.previous_is_last_output) m.contacts.Upload(in.previous->data(), in.previous->size(), stream);
  m.previous.swap(m.contacts);  // last output (or the caller's) becomes the history
  Check(cudaMemsetAsync(m.flag.data(), 0, sizeof(int), stream), "cudaMemset");
  Check(cudaEventRecord(m.events[1], stream), "cudaEventRecord");

  const std::size_t pairs = in.pair_count;
  Bodies bodies{position, cos_angle, sin_angle, velocity, angular_velocity, state, m.mass.data(), m.shape.data(),
                m.shape_family.data(), m.shape_scale.data(), m.families.data()};
  m.counts.set_size(pairs + 1);
  m.offsets.set_size(pairs + 1);
  constexpr unsigned kThreads = 128;
  const auto blocks = static_cast<unsigned>((pairs + 1 + kThreads - 1) / kThreads);
  CountContacts<<<blocks, kThreads, 0, stream>>>(bodies, m.box, m.pairs.data(), pairs, m.counts.data());
  Check(cudaGetLastError(), "CountContacts");
  std::size_t workspace = 0;
  Check(cub::DeviceScan::ExclusiveSum(nullptr, workspace, m.counts.data(), m.offsets.data(), pairs + 1, stream),
        "scan size");
  m.scan_workspace.set_size(workspace);
  Check(cub::DeviceScan::ExclusiveSum(m.scan_workspace.data(), workspace, m.counts.data(), m.offsets.data(),
                                      pairs + 1, stream),
        "scan");
  std::uint32_t total = 0;
  Check(cudaMemcpyAsync(&total, m.offsets.data() + pairs, sizeof(total), cudaMemcpyDeviceToHost, stream), "total");
  Check(cudaStreamSynchronize(stream), "count");
  m.contacts.set_size(total);
  const History history{m.previous.data(), m.previous.size()};
  if (pairs > 0)
    WriteContacts<<<static_cast<unsigned>((pairs + kThreads - 1) / kThreads), kThreads, 0, stream>>>(
        bodies, m.box, m.pairs.data(), pairs, m.offsets.data(), in.law, history, m.contacts.data(), m.flag.data());
  Check(cudaGetLastError(), "WriteContacts");
  // Each body's sums: its contacts listed in contact order by a stable radix
  // sort on the body (over the bits that body numbers use), then summed.
  const std::size_t entries = 2 * std::size_t{total};
  m.entry_body.set_size(entries);
  m.entry_index.set_size(entries);
  m.sorted_body.set_size(entries);
  m.sorted_index.set_size(entries);
  m.sums.set_size(n);
  if (total > 0) {
    ListBodyContacts<<<static_cast<unsigned>((total + kThreads - 1) / kThreads), kThreads, 0, stream>>>(
        m.contacts.data(), total, m.entry_body.data(), m.entry_index.data());
    Check(cudaGetLastError(), "ListBodyContacts");
    int bits = 1;
    while (bits < 32 && (std::size_t{1} << bits) < n) ++bits;
    std::size_t sort_bytes = 0;
    Check(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, m.entry_body.data(), m.sorted_body.data(),
                                          m.entry_index.data(), m.sorted_index.data(), entries, 0, bits, stream),
          "sort size");
    m.sort_workspace.set_size(sort_bytes);
    Check(cub::DeviceRadixSort::SortPairs(m.sort_workspace.data(), sort_bytes, m.entry_body.data(),
                                          m.sorted_body.data(), m.entry_index.data(), m.sorted_index.data(), entries,
                                          0, bits, stream),
          "sort");
  }
  if (n > 0) {
    SumPerBody<<<static_cast<unsigned>((n + kThreads - 1) / kThreads), kThreads, 0, stream>>>(
        m.contacts.data(), m.sorted_body.data(), m.sorted_index.data(), static_cast<std::uint32_t>(entries), position,
        m.box, static_cast<std::uint32_t>(n), m.sums.data());
    Check(cudaGetLastError(), "SumPerBody");
  }
  int beyond = 0;
  Check(cudaMemcpyAsync(&beyond, m.flag.data(), sizeof(int), cudaMemcpyDeviceToHost, stream), "flag");
  Check(cudaEventRecord(m.events[2], stream), "cudaEventRecord");
  // Through page-locked staging, then into the caller's list.
  unsigned char* staged = m.download_stage.Reserve(total * sizeof(Contact));
  if (total > 0)
    Check(cudaMemcpyAsync(staged, m.contacts.data(), total * sizeof(Contact), cudaMemcpyDeviceToHost, stream),
          "download");
  unsigned char* staged_sums = m.sums_stage.Reserve(n * sizeof(detail::BodySums));
  if (n > 0)
    Check(cudaMemcpyAsync(staged_sums, m.sums.data(), n * sizeof(detail::BodySums), cudaMemcpyDeviceToHost, stream),
          "download");
  Check(cudaEventRecord(m.events[3], stream), "cudaEventRecord");
  Check(cudaStreamSynchronize(stream), "download");
  // (Copied in one pass: resizing first would also write every record once.)
  const Contact* first = reinterpret_cast<const Contact*>(staged);
  out.insert(out.end(), first, first + total);
  const detail::BodySums* first_sums = reinterpret_cast<const detail::BodySums*>(staged_sums);
  body_sums.assign(first_sums, first_sums + n);
  float ms[3] = {};
  for (int k = 0; k < 3; ++k) Check(cudaEventElapsedTime(&ms[k], m.events[k], m.events[k + 1]), "timing");
  m.timing = {ms[0], ms[1], ms[2]};
  return beyond != 0;
}

}  // namespace crowdrecon::engine::cuda
