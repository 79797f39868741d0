// Binary encodings of the blocks' results (blocks.hpp, docs/blocks.md "Spilling and distributed runs"):
// what waits on disk between the passes and what a distributed engine's tasks pass to each other.
//
// Layout: the header (magic "VTRB", a byte-order mark 0x01020304 as written by this machine, the format
// version, the record kind), then the record's fields in a fixed order: scalars as their native bytes,
// arrays as a u64 count followed by the elements (Point3 as three doubles). Nothing is aligned; the reader
// copies every field out (memcpy), so a buffer at any address decodes.
#include "vitri/blocks.hpp"
#include "vitri/core/error.hpp"

#include <cstring>
#include <string>
#include <type_traits>

namespace vitri {
namespace {

constexpr char kMagic[4] = {'V', 'T', 'R', 'B'};
constexpr std::uint32_t kByteOrder = 0x01020304u;
constexpr std::uint32_t kVersion = 1;
enum class Kind : std::uint32_t { Seeds = 1, Surface = 2, Plan = 3 };

const char* kind_name(Kind k) {
  return k == Kind::Seeds ? "block seeds" : k == Kind::Surface ? "block surface" : "block plan";
}

class Writer {
 public:
  explicit Writer(Kind kind) {
    bytes(kMagic, 4);
    put(kByteOrder);
    put(kVersion);
    put(static_cast<std::uint32_t>(kind));
  }
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "plain data only");
    bytes(&v, sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    put(static_cast<std::uint64_t>(v.size()));
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
  std::vector<std::uint8_t> take() { return std::move(out_); }

 private:
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const std::uint8_t*>(p);
    out_.insert(out_.end(), c, c + n);
  }
  std::vector<std::uint8_t> out_;
};

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size, Kind kind) : data_(data), size_(size), kind_(kind) {
    if (!data && size) fail("no data");
    char magic[4];
    bytes(magic, 4);
    if (std::memcmp(magic, kMagic, 4) != 0) fail("not an encoding of vitri's blocks (no magic number)");
    if (get<std::uint32_t>() != kByteOrder) fail("written on a machine of another byte order");
    const auto version = get<std::uint32_t>();
    if (version != kVersion)
      fail("format version " + std::to_string(version) + ", this build reads version " + std::to_string(kVersion));
    const auto k = get<std::uint32_t>();
    if (k != static_cast<std::uint32_t>(kind))
      fail(std::string("holds a ") +
           (k >= 1 && k <= 3 ? kind_name(static_cast<Kind>(k)) : "record of unknown kind " + std::to_string(k)));
  }
  template <class T>
  T get() {
    T v;
    bytes(&v, sizeof(T));
    return v;
  }
  template <class T>
  void array(std::vector<T>& v) {
    const auto n = get<std::uint64_t>();
    if (n > (size_ - at_) / sizeof(T)) fail("an array of " + std::to_string(n) + " elements runs past the end");
    v.resize(static_cast<std::size_t>(n));
    if (n) bytes(v.data(), static_cast<std::size_t>(n) * sizeof(T));
  }
  void done() const {
    if (at_ != size_) fail(std::to_string(size_ - at_) + " bytes left over after the record");
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw InvalidArgument(std::string("decoding ") + kind_name(kind_) + " (" + std::to_string(size_) +
                          " bytes, at byte " + std::to_string(at_) + "): " + what);
  }
  void bytes(void* p, std::size_t n) {
    if (n > size_ - at_) fail("truncated (" + std::to_string(n) + " more bytes needed)");
    std::memcpy(p, data_ + at_, n);
    at_ += n;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
  Kind kind_;
};

}  // namespace

std::vector<std::uint8_t> encode_block_seeds(const BlockSeeds& s) {
  Writer w(Kind::Seeds);
  w.put(static_cast<std::int32_t>(s.block));
  w.array(s.points);
  w.array(s.values);
  w.array(s.gradients);
  w.array(s.ids);
  w.array(s.prepared.points);
  w.array(s.prepared.normals);
  w.array(s.prepared.spacing);
  w.array(s.prepared.set_aside);
  w.array(s.halo_points);
  w.array(s.halo_normals);
  w.put(static_cast<std::uint8_t>(s.flipped));
  w.put(static_cast<std::uint8_t>(s.budget_reached));
  w.put(s.resolution);
  w.put(s.precision);
  w.put(static_cast<std::uint64_t>(s.input_points));
  w.put(static_cast<std::uint64_t>(s.outliers));
  w.put(static_cast<std::uint64_t>(s.delaunay_vertices));
  w.put(s.seconds);
  return w.take();
}

BlockSeeds decode_block_seeds(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, Kind::Seeds);
  BlockSeeds s;
  s.block = r.get<std::int32_t>();
  r.array(s.points);
  r.array(s.values);
  r.array(s.gradients);
  r.array(s.ids);
  r.array(s.prepared.points);
  r.array(s.prepared.normals);
  r.array(s.prepared.spacing);
  r.array(s.prepared.set_aside);
  r.array(s.halo_points);
  r.array(s.halo_normals);
  s.flipped = r.get<std::uint8_t>() != 0;
  s.budget_reached = r.get<std::uint8_t>() != 0;
  s.resolution = r.get<double>();
  s.precision = r.get<double>();
  s.input_points = static_cast<std::size_t>(r.get<std::uint64_t>());
  s.outliers = static_cast<std::size_t>(r.get<std::uint64_t>());
  s.delaunay_vertices = static_cast<std::size_t>(r.get<std::uint64_t>());
  s.seconds = r.get<double>();
  r.done();
  if (s.values.size() != s.points.size() || s.gradients.size() != s.points.size() ||
      (!s.ids.empty() && s.ids.size() != s.points.size()) || s.halo_normals.size() != s.halo_points.size())
    throw InvalidArgument("decoding block seeds of block " + std::to_string(s.block) +
                          ": arrays of different lengths (points " + std::to_string(s.points.size()) + ", values " +
                          std::to_string(s.values.size()) + ", gradients " + std::to_string(s.gradients.size()) + ")");
  return s;
}

std::vector<std::uint8_t> encode_block_surface(const BlockSurface& s) {
  Writer w(Kind::Surface);
  w.put(static_cast<std::int32_t>(s.block));
  w.put(static_cast<std::uint64_t>(s.crossings.size()));
  for (const BlockCrossing& c : s.crossings) {
    w.put(c.neg);
    w.put(c.pos);
    w.put(c.x);
    w.put(c.normal);
    w.put(c.pos_point);
    w.put(static_cast<std::uint8_t>(c.anchored));
  }
  w.array(s.triangles);
  w.put(static_cast<std::uint64_t>(s.points));
  w.put(static_cast<std::uint64_t>(s.unfinished));
  w.put(s.halo);
  w.put(static_cast<std::int32_t>(s.rounds));
  w.put(s.seconds);
  return w.take();
}

BlockSurface decode_block_surface(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, Kind::Surface);
  BlockSurface s;
  s.block = r.get<std::int32_t>();
  const auto n = r.get<std::uint64_t>();
  constexpr std::size_t kCrossingBytes = 2 * sizeof(GlobalId) + 3 * sizeof(Point3) + 1;
  if (n > size / kCrossingBytes)
    throw InvalidArgument("decoding block surface (" + std::to_string(size) + " bytes): " + std::to_string(n) +
                          " crossings cannot fit");
  s.crossings.resize(static_cast<std::size_t>(n));
  for (BlockCrossing& c : s.crossings) {
    c.neg = r.get<GlobalId>();
    c.pos = r.get<GlobalId>();
    c.x = r.get<Point3>();
    c.normal = r.get<Point3>();
    c.pos_point = r.get<Point3>();
    c.anchored = r.get<std::uint8_t>() != 0;
  }
  r.array(s.triangles);
  s.points = static_cast<std::size_t>(r.get<std::uint64_t>());
  s.unfinished = static_cast<std::size_t>(r.get<std::uint64_t>());
  s.halo = r.get<double>();
  s.rounds = r.get<std::int32_t>();
  s.seconds = r.get<double>();
  r.done();
  for (const auto& t : s.triangles)
    for (std::uint32_t v : t)
      if (v >= s.crossings.size())
        throw InvalidArgument("decoding block surface of block " + std::to_string(s.block) + ": a triangle's corner " +
                              std::to_string(v) + " of " + std::to_string(s.crossings.size()) + " crossings");
  return s;
}

std::vector<std::uint8_t> encode_block_plan(const BlockPlan& p) {
  Writer w(Kind::Plan);
  w.put(p.grid.domain().lo);
  w.put(p.grid.domain().hi);
  for (int c : p.grid.counts()) w.put(static_cast<std::int32_t>(c));
  w.put(p.spacing);
  w.put(p.data_halo);
  return w.take();
}

BlockPlan decode_block_plan(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, Kind::Plan);
  Box3 domain;
  domain.lo = r.get<Point3>();
  domain.hi = r.get<Point3>();
  std::array<int, 3> counts{};
  for (int& c : counts) c = r.get<std::int32_t>();
  BlockPlan p;
  p.spacing = r.get<double>();
  p.data_halo = r.get<double>();
  r.done();
  p.grid = BlockGrid(domain, counts);  // validates the domain and the counts
  return p;
}

}  // namespace vitri
