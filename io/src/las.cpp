// LAS reader (the ASPRS LiDAR exchange format, versions 1.0 to 1.4, point data record formats 0 to 10).
//
// A LAS file is little-endian binary: a public header block, variable-length records (skipped), then
// the point records, each `record length` bytes. The header fields read here (byte offsets):
//
//   0   "LASF"                        file signature
//   24  version major, 25 minor       1.0 .. 1.4
//   94  header size (uint16)          at least 227
//   96  offset to point data (uint32)
//   104 point data record format      0 .. 10 (bit 7 set, or bits 6-7: LAZ compression, refused)
//   105 point data record length      at least 20 (formats 0-5) or 30 (formats 6-10)
//   107 legacy number of point records (uint32)
//   131 x, y, z scale factors, then x, y, z offsets (6 doubles)
//   247 number of point records (uint64, LAS 1.4: used when the legacy count is 0)
//
// Every record starts with X, Y, Z as int32: the coordinate is X x scale + offset. Formats 0-5 hold the
// classification in the low 5 bits of byte 15 and the "withheld" flag in bit 7; formats 6-10 hold the
// classification in byte 16 and the withheld flag in bit 2 of byte 15. Points classified as noise (7:
// low point, 18: high noise) or withheld are left out and counted in OrientedPoints::columns. Counts are
// checked against the bytes the file holds before anything is allocated.

#include "text.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

namespace vitri {

namespace {

template <class T>
T little(std::string_view b, std::size_t at) {
  return io_detail::load_little<T>(b.data() + at);
}

}  // namespace

OrientedPoints parse_las(std::string_view b, const std::string& name) {
  auto fail = [&](const std::string& what) { throw ParseError(name, 0, what); };
  if (b.size() < 4 || b.substr(0, 4) != "LASF") fail("not a LAS file (no 'LASF' signature)");
  if (b.size() < 227) fail("LAS header truncated: " + std::to_string(b.size()) + " bytes, at least 227 needed");
  const unsigned major = static_cast<unsigned char>(b[24]), minor = static_cast<unsigned char>(b[25]);
  if (major != 1 || minor > 4)
    fail("LAS version " + std::to_string(major) + "." + std::to_string(minor) + " is not read (1.0 to 1.4)");
  const std::size_t header_size = little<std::uint16_t>(b, 94);
  const std::size_t offset = little<std::uint32_t>(b, 96);
  const unsigned format_byte = static_cast<unsigned char>(b[104]);
  if (format_byte & 0xC0)
    fail("LAZ-compressed point data (record format byte " + std::to_string(format_byte) +
         "): decompress it first (laszip, or PDAL's `pdal translate in.laz out.las`)");
  const unsigned format = format_byte;
  if (format > 10) fail("LAS point data record format " + std::to_string(format) + " is unknown (0 to 10)");
  const std::size_t record = little<std::uint16_t>(b, 105);
  const std::size_t least = format <= 5 ? 20 : 30;
  if (record < least)
    fail("LAS point record length " + std::to_string(record) + " is below format " + std::to_string(format) +
         "'s " + std::to_string(least) + " bytes");
  std::uint64_t count = little<std::uint32_t>(b, 107);
  if (count == 0 && minor >= 4 && header_size >= 255 && b.size() >= 255) count = little<std::uint64_t>(b, 247);
  double scale[3], shift[3];
  for (int a = 0; a < 3; ++a) {
    scale[a] = little<double>(b, 131 + 8 * static_cast<std::size_t>(a));
    shift[a] = little<double>(b, 155 + 8 * static_cast<std::size_t>(a));
    if (!std::isfinite(scale[a]) || scale[a] == 0 || !std::isfinite(shift[a]))
      fail("LAS header: scale or offset of " + std::string(1, "xyz"[a]) + " is zero or not finite");
  }
  if (header_size < 227 || offset < header_size || offset > b.size())
    fail("LAS header: point data offset " + std::to_string(offset) + " outside the file (" +
         std::to_string(b.size()) + " bytes, header " + std::to_string(header_size) + ")");
  if (count > (b.size() - offset) / record)
    fail("LAS header declares " + std::to_string(count) + " points of " + std::to_string(record) +
         " bytes, the file holds " + std::to_string((b.size() - offset) / record));
  OrientedPoints p;
  p.points.reserve(static_cast<std::size_t>(count));
  std::size_t noise = 0, withheld = 0;
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::size_t at = offset + static_cast<std::size_t>(i) * record;
    const unsigned flags = static_cast<unsigned char>(b[at + 15]);
    const unsigned cls = format <= 5 ? (flags & 0x1Fu) : static_cast<unsigned char>(b[at + 16]);
    const bool held = format <= 5 ? (flags & 0x80u) != 0 : (flags & 0x04u) != 0;
    if (held) {
      ++withheld;
      continue;
    }
    if (cls == 7 || cls == 18) {
      ++noise;
      continue;
    }
    Point3 q;
    for (int a = 0; a < 3; ++a)
      q[static_cast<std::size_t>(a)] =
          static_cast<double>(little<std::int32_t>(b, at + 4 * static_cast<std::size_t>(a))) * scale[a] + shift[a];
    p.points.push_back(q);
  }
  if (p.points.empty())
    fail("no point in file (" + std::to_string(count) + " records, " + std::to_string(noise) + " noise, " +
         std::to_string(withheld) + " withheld)");
  std::string note = "LAS " + std::to_string(major) + "." + std::to_string(minor) + ", record format " +
                     std::to_string(format) + ", " + std::to_string(count) + " points";
  if (noise) note += "; " + std::to_string(noise) + " classified as noise (7, 18) left out";
  if (withheld) note += "; " + std::to_string(withheld) + " withheld left out";
  p.columns = note;
  return p;
}

}  // namespace vitri
