// PCD reader (the Point Cloud Library's format): DATA ascii, binary and binary_compressed.
//
// A PCD file is a text header, one keyword per line, that ends with the DATA line; the points follow:
//
//   # .PCD v0.7 - Point Cloud Data file format     comments start with '#'
//   VERSION 0.7
//   FIELDS x y z rgb                 field names; each field has a SIZE in bytes (1, 2, 4, 8), a TYPE
//   SIZE 4 4 4 4                     (I signed, U unsigned, F float) and a COUNT (values per point);
//   TYPE F F F U                     SIZE, TYPE, COUNT default to 4, F, 1 when their line is absent
//   COUNT 1 1 1 1
//   WIDTH 640                        organized cloud: HEIGHT rows of WIDTH pixels, NaN where no return
//   HEIGHT 480
//   VIEWPOINT 0 0 0 1 0 0 0          sensor pose: translation tx ty tz, then quaternion qw qx qy qz
//   POINTS 307200                    = WIDTH x HEIGHT
//   DATA binary                      ascii | binary | binary_compressed
//
// - ascii: one point per line, the fields' values in FIELDS order (COUNT values for a field).
// - binary: POINTS records, each the fields' values in order (SIZE x COUNT bytes a field), little endian.
// - binary_compressed: uint32 compressed size, uint32 uncompressed size, then that many LZF bytes, which
//   decompress to the same values in structure-of-arrays order: every point's first field, then every
//   point's second field, ... The "_" fields (padding that PCL declares for alignment) are absent there,
//   as PCL writes and reads them; in ascii and binary they are ordinary skipped fields.
//
// Only x y z and normal_x normal_y normal_z are read; every other field is skipped by its size. A point
// with a non-finite coordinate (PCL's "no measurement") is skipped; the rule for non-finite normals is in
// settle_normals(). Every count is checked against the bytes that could hold it before anything is
// allocated, and the LZF sizes against LZF's largest expansion.

#include "text.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <lzf.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace vitri {

using io_detail::LineScanner;

namespace {

enum class PcdData { Ascii, Binary, BinaryCompressed };

// An LZF back reference of 3 bytes copies at most 7 + 255 + 2 = 264 bytes: no LZF stream decompresses to
// more than 88 times its size. A larger declared size is a corrupt header, refused before allocating.
constexpr std::uint64_t kLzfMaxExpansion = 88;

// Bytes of one point beyond which a header is refused as absurd (and sums of field sizes stay far from
// overflowing): 2^40.
constexpr std::uint64_t kMaxPointBytes = std::uint64_t{1} << 40;

struct PcdField {
  std::string name;
  std::size_t size = 4;   // bytes of one value (SIZE)
  char type = 'F';        // I, U or F (TYPE)
  std::size_t count = 1;  // values per point (COUNT)
};

// The fields read: positions and normals, by slot.
enum Slot : std::size_t { kX, kY, kZ, kNx, kNy, kNz, kSlots };
constexpr std::array<const char*, kSlots> kSlotNames = {"x", "y", "z", "normal_x", "normal_y", "normal_z"};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t point_bytes = 0;           // SIZE x COUNT summed over the fields: a binary record
  std::uint64_t packed_bytes = 0;          // the same without the "_" fields: a point in binary_compressed
  std::array<std::size_t, kSlots> slot{};  // field index of each slot (normals: valid when `normals`)
  bool normals = false;
  std::uint64_t points = 0;
  std::size_t points_line = 0;
  std::optional<Point3> viewpoint;
  PcdData data = PcdData::Ascii;
  std::size_t data_offset = 0;  // first byte after the DATA line
};

// A token for an error message: at most 40 characters, bytes outside printable ASCII as '?' (a binary
// payload read as a header line must not end up raw in a message).
std::string shown(std::string_view t) {
  std::string s(t.substr(0, 40));
  for (char& c : s)
    if (c < 0x20 || c > 0x7e) c = '?';
  if (t.size() > 40) s += "...";
  return s;
}

// a * b, or nothing when the product exceeds 2^64 - 1.
std::optional<std::uint64_t> product(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return std::nullopt;
  return a * b;
}

// The header, up to and including the DATA line. Keywords may come in any order (PCL's readers need
// FIELDS before SIZE, TYPE, COUNT; this one checks them together at DATA); each at most once.
PcdHeader parse_header(LineScanner& s) {
  const std::string& name = s.name();
  PcdHeader h;
  std::vector<std::string> names;
  std::vector<std::size_t> sizes, counts;
  std::vector<char> types;
  long long width = -1, height = -1, points = -1;
  // Line of each keyword (0: not seen).
  std::size_t version_at = 0, fields_at = 0, size_at = 0, type_at = 0, count_at = 0, width_at = 0,
              height_at = 0, viewpoint_at = 0, points_at = 0;
  constexpr long long kMaxCount = std::numeric_limits<long long>::max();
  for (;;) {
    if (!s.next_data_line()) throw ParseError(name, s.line(), "PCD header ends without a DATA line");
    const auto& t = s.tokens();
    const std::string_view key = t[0];
    auto once = [&](std::size_t& at) {
      if (at != 0) s.fail(std::string(key) + " given twice (first on line " + std::to_string(at) + ")");
      at = s.line();
    };
    auto single_count = [&](std::size_t& at) {
      once(at);
      long long v = -1;
      const std::string_view tok = t.size() == 2 ? t[1] : std::string_view();
      const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      if (t.size() != 2 || r.ec != std::errc() || r.ptr != tok.data() + tok.size() || v < 0)
        s.fail("expected '" + std::string(key) + " N', N a count from 0 to " + std::to_string(kMaxCount) +
               (t.size() == 2 ? ", got '" + shown(tok) + "'" : std::string()));
      return v;
    };
    if (key == "VERSION") {
      once(version_at);                                // not checked: PCL reads 0.5 to 0.7 alike
    } else if (key == "FIELDS" || key == "COLUMNS") {  // COLUMNS: PCL's older name
      once(fields_at);
      if (t.size() < 2) s.fail("FIELDS names no field");
      for (std::size_t k = 1; k < t.size(); ++k) names.emplace_back(t[k]);
    } else if (key == "SIZE") {
      once(size_at);
      for (std::size_t k = 1; k < t.size(); ++k) {
        const auto v = static_cast<std::size_t>(s.integer(k, 0, std::numeric_limits<int>::max()));
        if (v != 1 && v != 2 && v != 4 && v != 8)
          s.fail("SIZE " + std::to_string(v) + " in column " + std::to_string(k) +
                 " (expected 1, 2, 4 or 8)");
        sizes.push_back(v);
      }
    } else if (key == "TYPE") {
      once(type_at);
      for (std::size_t k = 1; k < t.size(); ++k) {
        if (t[k] != "I" && t[k] != "U" && t[k] != "F")
          s.fail("TYPE '" + shown(t[k]) + "' in column " + std::to_string(k) + " (expected I, U or F)");
        types.push_back(t[k][0]);
      }
    } else if (key == "COUNT") {
      once(count_at);
      for (std::size_t k = 1; k < t.size(); ++k)
        counts.push_back(static_cast<std::size_t>(s.integer(k, 0, std::numeric_limits<int>::max())));
    } else if (key == "WIDTH") {
      width = single_count(width_at);
    } else if (key == "HEIGHT") {
      height = single_count(height_at);
    } else if (key == "POINTS") {
      points = single_count(points_at);
    } else if (key == "VIEWPOINT") {
      once(viewpoint_at);
      if (t.size() != 8)
        s.fail("VIEWPOINT needs 7 numbers 'tx ty tz qw qx qy qz', got " + std::to_string(t.size() - 1));
      h.viewpoint = Point3{s.number(1), s.number(2), s.number(3)};
      for (std::size_t k = 4; k < 8; ++k) (void)s.number(k);  // the orientation: checked, not kept
    } else if (key == "DATA") {
      if (t.size() != 2) s.fail("expected 'DATA ascii', 'DATA binary' or 'DATA binary_compressed'");
      if (t[1] == "ascii")
        h.data = PcdData::Ascii;
      else if (t[1] == "binary")
        h.data = PcdData::Binary;
      else if (t[1] == "binary_compressed")
        h.data = PcdData::BinaryCompressed;
      else
        s.fail("unsupported DATA '" + shown(t[1]) + "' (expected ascii, binary or binary_compressed)");
      h.data_offset = s.offset();
      break;
    } else {
      s.fail("unknown PCD header keyword '" + shown(key) +
             "' (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS or DATA)");
    }
  }
  const std::size_t data_at = s.line();

  // Fields: SIZE, TYPE, COUNT give one value per field.
  if (fields_at == 0) throw ParseError(name, data_at, "no FIELDS line before DATA");
  const std::size_t n = names.size();
  auto same_length = [&](std::size_t got, std::size_t at, const char* what) {
    if (at != 0 && got != n)
      throw ParseError(name, at,
                       std::string(what) + " gives " + std::to_string(got) + " values for the " +
                           std::to_string(n) + " fields of FIELDS (line " + std::to_string(fields_at) + ")");
  };
  same_length(sizes.size(), size_at, "SIZE");
  same_length(types.size(), type_at, "TYPE");
  same_length(counts.size(), count_at, "COUNT");
  h.fields.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    PcdField& f = h.fields[i];
    f.name = names[i];
    if (size_at) f.size = sizes[i];
    if (type_at) f.type = types[i];
    if (count_at) f.count = counts[i];
    // Each term is below 2^34 (SIZE <= 8, COUNT < 2^31), checked after each: no sum can overflow. The
    // values of an ascii line (COUNT summed) are fewer than these bytes.
    h.point_bytes += f.size * f.count;
    if (f.name != "_") h.packed_bytes += f.size * f.count;
    if (h.point_bytes > kMaxPointBytes)
      throw ParseError(
          name, count_at ? count_at : fields_at,
          "a point of more than " + std::to_string(kMaxPointBytes) + " bytes (SIZE x COUNT summed)");
  }

  // The fields read: x y z required, normals all three or none, each a single float or double.
  std::array<bool, kSlots> found{};
  for (std::size_t i = 0; i < n; ++i) {
    const PcdField& f = h.fields[i];
    for (std::size_t k = 0; k < kSlots; ++k) {
      if (f.name != kSlotNames[k]) continue;
      if (found[k]) throw ParseError(name, fields_at, "field '" + f.name + "' listed twice in FIELDS");
      found[k] = true;
      h.slot[k] = i;
      if (f.type != 'F')
        throw ParseError(name, type_at, "field '" + f.name + "' has TYPE " + f.type + " (expected F: float)");
      if (f.size != 4 && f.size != 8)
        throw ParseError(name, size_at,
                         "field '" + f.name + "' has SIZE " + std::to_string(f.size) +
                             " (expected 4 or 8: float or double)");
      if (f.count != 1)
        throw ParseError(name, count_at,
                         "field '" + f.name + "' has COUNT " + std::to_string(f.count) + " (expected 1)");
    }
  }
  std::string missing;
  for (std::size_t k = kX; k <= kZ; ++k)
    if (!found[k]) missing += std::string(missing.empty() ? "" : ", ") + kSlotNames[k];
  if (!missing.empty())
    throw ParseError(name, fields_at, "FIELDS lacks " + missing + " (x y z are required)");
  const int normal_fields = int{found[kNx]} + int{found[kNy]} + int{found[kNz]};
  if (normal_fields != 0 && normal_fields != 3)
    throw ParseError(
        name, fields_at,
        "FIELDS has " + std::to_string(normal_fields) + " of normal_x normal_y normal_z (all three or none)");
  h.normals = normal_fields == 3;

  // Counts: POINTS = WIDTH x HEIGHT; WIDTH alone means HEIGHT 1, neither means an unorganized cloud.
  if (points_at == 0) throw ParseError(name, data_at, "no POINTS line before DATA");
  if (points == 0) throw ParseError(name, points_at, "POINTS 0: no point in file");
  if (height_at != 0 && width_at == 0) throw ParseError(name, height_at, "HEIGHT given without WIDTH");
  if (width_at != 0) {
    const auto w = static_cast<std::uint64_t>(width);
    const auto hh = static_cast<std::uint64_t>(height_at != 0 ? height : 1);
    const auto wh = product(w, hh);
    if (!wh || *wh != static_cast<std::uint64_t>(points))
      throw ParseError(name, points_at,
                       "POINTS " + std::to_string(points) + " differs from WIDTH " + std::to_string(w) +
                           " x HEIGHT " + std::to_string(hh) +
                           (wh ? " = " + std::to_string(*wh) : std::string(" (overflows)")));
  }
  h.points = static_cast<std::uint64_t>(points);
  h.points_line = points_at;
  return h;
}

// A little-endian float or double at p.
double load(const unsigned char* p, std::size_t size) {
  return size == 4 ? static_cast<double>(io_detail::load_little<float>(p)) : io_detail::load_little<double>(p);
}

bool all_finite(const Point3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// Non-finite normals (PCL's normal estimation writes NaN where a point has too few neighbours): when at
// least one point has a finite normal, the points without one are skipped and the normals kept; when no
// point has one, the normals are dropped and every point kept.
void settle_normals(OrientedPoints& p) {
  const auto good = static_cast<std::size_t>(std::count_if(p.normals.begin(), p.normals.end(), all_finite));
  if (good == p.normals.size()) return;
  if (good == 0) {
    p.normals.clear();
    return;
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    if (!all_finite(p.normals[i])) continue;
    p.points[kept] = p.points[i];
    p.normals[kept] = p.normals[i];
    ++kept;
  }
  p.points.resize(kept);
  p.normals.resize(kept);
}

// Where each slot's values lie in a binary payload: value of point i at base + i * stride.
struct Column {
  const unsigned char* base = nullptr;
  std::size_t stride = 0;
  std::size_t size = 4;
};

void decode_columns(const PcdHeader& h, const std::array<Column, kSlots>& col, OrientedPoints& out) {
  const auto at = [&](std::size_t k, std::size_t i) {
    return load(col[k].base + i * col[k].stride, col[k].size);
  };
  for (std::size_t i = 0; i < h.points; ++i) {
    const Point3 p{at(kX, i), at(kY, i), at(kZ, i)};
    if (!all_finite(p)) continue;
    out.points.push_back(p);
    if (h.normals) out.normals.push_back({at(kNx, i), at(kNy, i), at(kNz, i)});
  }
}

void read_binary(std::string_view bytes, const std::string& name, const PcdHeader& h, OrientedPoints& out) {
  const std::uint64_t record = h.point_bytes;
  const std::size_t left = bytes.size() - h.data_offset;
  const auto need = product(h.points, record);
  if (!need || *need > left)
    throw ParseError(name, 0,
                     "binary data truncated: POINTS " + std::to_string(h.points) + " x " +
                         std::to_string(record) + " bytes per point need " +
                         (need ? std::to_string(*need) : std::string("more than 2^64")) +
                         " bytes after the header (byte offset " + std::to_string(h.data_offset) +
                         "), the file has " + std::to_string(left));
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data()) + h.data_offset;
  std::array<Column, kSlots> col;
  std::size_t offset = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    for (std::size_t k = 0; k < kSlots; ++k)
      if (h.slot[k] == i && (k <= kZ || h.normals)) col[k] = {data + offset, record, h.fields[i].size};
    offset += h.fields[i].size * h.fields[i].count;
  }
  out.points.reserve(h.points);  // <= the bytes left / record
  if (h.normals) out.normals.reserve(h.points);
  decode_columns(h, col, out);
}

void read_compressed(std::string_view bytes, const std::string& name, const PcdHeader& h,
                     OrientedPoints& out) {
  const std::size_t at = h.data_offset;
  const std::size_t left = bytes.size() - at;
  if (left < 8)
    throw ParseError(
        name, 0,
        "binary_compressed data truncated: the compressed and uncompressed sizes (8 bytes) do not "
        "fit at byte offset " +
            std::to_string(at));
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data()) + at;
  auto u32 = [&](std::size_t k) {
    std::uint32_t v = 0;
    for (std::size_t j = 0; j < 4; ++j) v |= static_cast<std::uint32_t>(data[k + j]) << (8 * j);
    return v;
  };
  const std::uint32_t compressed = u32(0), uncompressed = u32(4);
  if (compressed > left - 8)
    throw ParseError(name, 0,
                     "binary_compressed: compressed size " + std::to_string(compressed) +
                         " runs past the end of the file (" + std::to_string(left - 8) +
                         " bytes left at byte offset " + std::to_string(at + 8) + ")");
  const std::uint64_t packed = h.packed_bytes;
  const auto expected = product(h.points, packed);
  if (!expected || *expected != uncompressed)
    throw ParseError(name, 0,
                     "binary_compressed: uncompressed size " + std::to_string(uncompressed) +
                         " (byte offset " + std::to_string(at + 4) + ") differs from POINTS " +
                         std::to_string(h.points) + " x " + std::to_string(packed) + " bytes per point" +
                         (expected ? " = " + std::to_string(*expected) : std::string(" (overflows)")));
  if (uncompressed > kLzfMaxExpansion * compressed)
    throw ParseError(name, 0,
                     "binary_compressed: " + std::to_string(compressed) + " bytes of LZF data cannot hold " +
                         std::to_string(uncompressed) + " bytes (LZF expands at most 88 times; byte offset " +
                         std::to_string(at) + ")");
  std::vector<unsigned char> buf(uncompressed);
  errno = 0;
  const unsigned got = lzf_decompress(data + 8, compressed, buf.data(), uncompressed);
  if (got != uncompressed) {
    const int err = errno;
    throw ParseError(name, 0,
                     "binary_compressed: LZF decompression of the " + std::to_string(compressed) +
                         " bytes at byte offset " + std::to_string(at + 8) + " failed: " +
                         (got == 0 && err == E2BIG ? "the data decompress to more than the declared " +
                                                         std::to_string(uncompressed) + " bytes"
                          : got == 0 ? std::string("corrupt LZF data")
                                     : "the data decompress to " + std::to_string(got) +
                                           " bytes, the header declares " + std::to_string(uncompressed)));
  }
  // Structure of arrays: field i's values of every point follow field i-1's ("_" fields absent).
  std::array<Column, kSlots> col;
  std::uint64_t offset = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    const PcdField& f = h.fields[i];
    if (f.name == "_") continue;
    for (std::size_t k = 0; k < kSlots; ++k)
      if (h.slot[k] == i && (k <= kZ || h.normals)) col[k] = {buf.data() + offset, f.size, f.size};
    offset += h.points * f.size * f.count;  // <= uncompressed: no overflow
  }
  out.points.reserve(h.points);  // POINTS x packed = uncompressed <= 88 x the file's size
  if (h.normals) out.normals.reserve(h.points);
  decode_columns(h, col, out);
}

// A number of an ascii field: float for SIZE 4 (the value a binary file would hold), else double. NaN
// and infinities are accepted here ("nan" marks a missing point) and dealt with by the caller.
double ascii_value(const LineScanner& s, std::string_view t, std::size_t size, std::size_t point,
                   const char* field) {
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (b != e && *b == '+') ++b;
  double v = 0;
  std::from_chars_result r{};
  if (size == 4) {
    float f = 0;
    r = std::from_chars(b, e, f);
    v = static_cast<double>(f);
  } else {
    r = std::from_chars(b, e, v);
  }
  if (r.ec == std::errc::result_out_of_range)
    s.fail("point " + std::to_string(point) + ": field '" + field + "': '" + shown(t) +
           "' is out of range for " + (size == 4 ? "a float" : "a double"));
  if (r.ec != std::errc() || r.ptr != e)
    s.fail("point " + std::to_string(point) + ": field '" + field + "': not a number: '" + shown(t) + "'");
  return v;
}

void read_ascii(std::string_view bytes, LineScanner& s, const PcdHeader& h, OrientedPoints& out) {
  const std::size_t lines =
      static_cast<std::size_t>(
          std::count(bytes.begin() + static_cast<std::ptrdiff_t>(h.data_offset), bytes.end(), '\n')) +
      1;
  if (h.points > lines)
    throw ParseError(s.name(), h.points_line,
                     "POINTS " + std::to_string(h.points) + " exceeds the " + std::to_string(lines) +
                         " lines after the header (truncated?)");
  // Token of each slot on a data line.
  std::array<std::size_t, kSlots> token{};
  std::size_t values = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    for (std::size_t k = 0; k < kSlots; ++k)
      if (h.slot[k] == i) token[k] = values;
    values += h.fields[i].count;
  }
  out.points.reserve(h.points);  // <= the lines left
  if (h.normals) out.normals.reserve(h.points);
  for (std::size_t i = 0; i < h.points; ++i) {
    if (!s.next_data_line())
      s.fail("file ends after " + std::to_string(i) + " of the " + std::to_string(h.points) + " points");
    if (s.tokens().size() != values)
      s.fail("point " + std::to_string(i) + ": expected " + std::to_string(values) +
             " values (the fields' COUNTs), got " + std::to_string(s.tokens().size()));
    auto at = [&](std::size_t k) {
      return ascii_value(s, s.tokens()[token[k]], h.fields[h.slot[k]].size, i, kSlotNames[k]);
    };
    const Point3 p{at(kX), at(kY), at(kZ)};
    if (!all_finite(p)) continue;
    out.points.push_back(p);
    if (h.normals) out.normals.push_back({at(kNx), at(kNy), at(kNz)});
  }
  if (s.next_data_line())
    s.fail("data line beyond POINTS " + std::to_string(h.points) + " (line " + std::to_string(h.points_line) +
           ")");
}

}  // namespace

OrientedPoints parse_pcd(std::string_view bytes, const std::string& name) {
  LineScanner s(bytes, name);
  const PcdHeader h = parse_header(s);
  OrientedPoints out;
  switch (h.data) {
    case PcdData::Ascii:
      read_ascii(bytes, s, h, out);
      break;
    case PcdData::Binary:
      read_binary(bytes, name, h, out);
      break;
    case PcdData::BinaryCompressed:
      read_compressed(bytes, name, h, out);
      break;
  }
  if (out.points.empty())
    throw ParseError(
        name, 0, "no valid point: all " + std::to_string(h.points) + " points have a non-finite x, y or z");
  settle_normals(out);
  out.viewpoint = h.viewpoint;
  return out;
}

}  // namespace vitri
