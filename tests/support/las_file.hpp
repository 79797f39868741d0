#pragma once
// LAS (ASPRS LiDAR) files written by hand for the tests, little-endian: the header's fields at their
// offsets (version 1.minor, point format `format`, `record` bytes per point, scale 0.01 0.01 0.001 and
// offset 1000 2000 -5), then one record per point: its integer coordinates, its class and withheld flag.
#include "vitri/io/io.hpp"

#include "../../io/src/text.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vitri::test {

inline std::string las_file(unsigned minor, unsigned format, std::size_t record,
                            const std::vector<std::array<std::int32_t, 3>>& xyz, const std::vector<unsigned>& classes,
                            const std::vector<bool>& withheld) {
  std::string b(227, '\0');
  auto put = [&](std::size_t at, const void* v, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(v);
    for (std::size_t i = 0; i < n; ++i) b[at + i] = static_cast<char>(c[vitri::io_detail::host_little_endian() ? i : n - 1 - i]);
  };
  b.replace(0, 4, "LASF");
  b[24] = 1;
  b[25] = static_cast<char>(minor);
  const std::uint16_t header = 227, length = static_cast<std::uint16_t>(record);
  const std::uint32_t offset = 227, count = static_cast<std::uint32_t>(xyz.size());
  put(94, &header, 2);
  put(96, &offset, 4);
  b[104] = static_cast<char>(format);
  put(105, &length, 2);
  put(107, &count, 4);
  const double scale[3] = {0.01, 0.01, 0.001}, shift[3] = {1000, 2000, -5};
  for (int a = 0; a < 3; ++a) {
    put(131 + 8 * a, &scale[a], 8);
    put(155 + 8 * a, &shift[a], 8);
  }
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    std::string r(record, '\0');
    const std::size_t at = b.size();
    b += r;
    for (int a = 0; a < 3; ++a) put(at + 4 * a, &xyz[i][a], 4);
    if (format <= 5) {
      b[at + 15] = static_cast<char>((classes[i] & 0x1F) | (withheld[i] ? 0x80 : 0));
    } else {
      b[at + 15] = static_cast<char>(withheld[i] ? 0x04 : 0);
      b[at + 16] = static_cast<char>(classes[i]);
    }
  }
  return b;
}


}  // namespace vitri::test
