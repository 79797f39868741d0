// PLY reader (ascii 1.0, binary_little_endian 1.0, binary_big_endian 1.0).
//
// The header is parsed into elements with their properties; the vertex element gives x y z (and nx ny
// nz, and the sensor positions vx vy vz, each when all three are present), the face element a list named
// vertex_indices or vertex_index; every other element or property is skipped by its declared type.
// Binary reads are bounds-checked against the buffer, and element counts are checked against the bytes
// (binary) or lines (ascii) left before any allocation, so a corrupt header cannot make the reader
// allocate or read out of bounds.

#include "text.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>

namespace vitri {

using io_detail::LineScanner;

namespace {

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::U8;  // lists only
  PlyType type = PlyType::F32;       // scalar type, or item type of a list
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::size_t header_line = 0;
  std::vector<PlyProperty> props;
};

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::I8:
    case PlyType::U8:
      return 1;
    case PlyType::I16:
    case PlyType::U16:
      return 2;
    case PlyType::I32:
    case PlyType::U32:
    case PlyType::F32:
      return 4;
    case PlyType::F64:
      return 8;
  }
  return 1;
}

bool is_integer(PlyType t) {
  return t != PlyType::F32 && t != PlyType::F64;
}

PlyType parse_type(const LineScanner& s, std::string_view t) {
  if (t == "char" || t == "int8") return PlyType::I8;
  if (t == "uchar" || t == "uint8") return PlyType::U8;
  if (t == "short" || t == "int16") return PlyType::I16;
  if (t == "ushort" || t == "uint16") return PlyType::U16;
  if (t == "int" || t == "int32") return PlyType::I32;
  if (t == "uint" || t == "uint32") return PlyType::U32;
  if (t == "float" || t == "float32") return PlyType::F32;
  if (t == "double" || t == "float64") return PlyType::F64;
  s.fail("unknown PLY property type '" + std::string(t) + "'");
}

// Bounds-checked reader over the binary payload, in the file's byte order.
class BinaryReader {
 public:
  BinaryReader(std::string_view bytes, std::size_t offset, const std::string& name, bool big_endian)
      : bytes_(bytes), pos_(offset), name_(name), swap_(big_endian == io_detail::host_little_endian()) {}

  double read(PlyType t, const char* what, std::size_t index) {
    const std::size_t n = type_size(t);
    if (pos_ + n > bytes_.size())
      throw ParseError(name_, 0,
                       std::string("binary PLY truncated in ") + what + " " + std::to_string(index) +
                           " at byte offset " + std::to_string(pos_));
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + pos_, n);
    if (swap_) std::reverse(b, b + n);
    pos_ += n;
    switch (t) {
      case PlyType::I8:
        return static_cast<double>(static_cast<std::int8_t>(b[0]));
      case PlyType::U8:
        return static_cast<double>(b[0]);
      case PlyType::I16: {
        std::int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::U16: {
        std::uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::I32: {
        std::int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::U32: {
        std::uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::F32: {
        float v;
        std::memcpy(&v, b, 4);
        return static_cast<double>(v);
      }
      case PlyType::F64: {
        double v;
        std::memcpy(&v, b, 8);
        return v;
      }
    }
    return 0;
  }
  std::size_t left() const { return bytes_.size() - std::min(pos_, bytes_.size()); }
  std::size_t offset() const { return pos_; }

 private:
  std::string_view bytes_;
  std::size_t pos_;
  const std::string& name_;
  bool swap_;
};

// Minimum bytes of one record of an element (lists count their length field only).
std::size_t min_record_size(const PlyElement& e) {
  std::size_t s = 0;
  for (const auto& p : e.props) s += p.is_list ? type_size(p.count_type) : type_size(p.type);
  return s;
}

}  // namespace

TriangleMesh parse_ply(std::string_view bytes, const std::string& name) {
  std::vector<Point3> sensors;
  return io_detail::parse_ply_with_sensors(bytes, name, sensors);
}

TriangleMesh io_detail::parse_ply_with_sensors(std::string_view bytes, const std::string& name,
                                               std::vector<Point3>& sensors) {
  sensors.clear();
  LineScanner s(bytes, name, /*comments=*/false);
  if (!s.next_data_line() || s.tokens()[0] != "ply")
    throw ParseError(name, 1, "not a PLY file (missing 'ply')");
  bool binary = false, big_endian = false, have_format = false;
  std::vector<PlyElement> elements;
  for (;;) {
    if (!s.next_data_line()) s.fail("header ends without 'end_header'");
    const auto& t = s.tokens();
    if (t[0] == "end_header") break;
    if (t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "format") {
      if (t.size() < 2) s.fail("format line without a format");
      if (t[1] == "ascii")
        binary = false;
      else if (t[1] == "binary_little_endian")
        binary = true;
      else if (t[1] == "binary_big_endian")
        binary = big_endian = true;  // (older scanners' and tools' files: byte-swapped as read)
      else
        s.fail("unknown PLY format '" + std::string(t[1]) + "'");
      have_format = true;
    } else if (t[0] == "element") {
      if (t.size() != 3) s.fail("expected 'element NAME COUNT'");
      PlyElement e;
      e.name = std::string(t[1]);
      e.count = static_cast<std::size_t>(s.integer(2, 0, std::numeric_limits<int>::max()));
      e.header_line = s.line();
      elements.push_back(std::move(e));
    } else if (t[0] == "property") {
      if (elements.empty()) s.fail("property before any element");
      PlyProperty p;
      if (t.size() >= 2 && t[1] == "list") {
        if (t.size() != 5) s.fail("expected 'property list COUNT_TYPE ITEM_TYPE NAME'");
        p.is_list = true;
        p.count_type = parse_type(s, t[2]);
        p.type = parse_type(s, t[3]);
        if (!is_integer(p.count_type)) s.fail("list count type must be an integer type");
        p.name = std::string(t[4]);
      } else {
        if (t.size() != 3) s.fail("expected 'property TYPE NAME'");
        p.type = parse_type(s, t[1]);
        p.name = std::string(t[2]);
      }
      elements.back().props.push_back(std::move(p));
    } else {
      s.fail("unknown PLY header keyword '" + std::string(t[0]) + "'");
    }
  }
  if (!have_format) s.fail("PLY header without a 'format' line");

  const PlyElement* ve = nullptr;
  const PlyElement* fe = nullptr;
  for (const auto& e : elements) {
    if (e.name == "vertex" && !ve) ve = &e;
    if (e.name == "face" && !fe) fe = &e;
  }
  if (!ve) throw ParseError(name, s.line(), "PLY file has no 'vertex' element");
  int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, ivx = -1, ivy = -1, ivz = -1, ilist = -1;
  for (std::size_t k = 0; k < ve->props.size(); ++k) {
    const auto& p = ve->props[k];
    if (p.is_list) continue;
    const int kk = static_cast<int>(k);
    if (p.name == "x") ix = kk;
    if (p.name == "y") iy = kk;
    if (p.name == "z") iz = kk;
    if (p.name == "nx") inx = kk;
    if (p.name == "ny") iny = kk;
    if (p.name == "nz") inz = kk;
    if (p.name == "vx") ivx = kk;
    if (p.name == "vy") ivy = kk;
    if (p.name == "vz") ivz = kk;
  }
  if (ix < 0 || iy < 0 || iz < 0) throw ParseError(name, ve->header_line, "vertex element lacks x, y or z");
  const bool normals = inx >= 0 && iny >= 0 && inz >= 0;
  const bool with_sensors = ivx >= 0 && ivy >= 0 && ivz >= 0;
  if (fe) {
    for (std::size_t k = 0; k < fe->props.size(); ++k)
      if (fe->props[k].is_list &&
          (fe->props[k].name == "vertex_indices" || fe->props[k].name == "vertex_index"))
        ilist = static_cast<int>(k);
    if (ilist < 0) throw ParseError(name, fe->header_line, "face element lacks a vertex_indices list");
    if (!is_integer(fe->props[static_cast<std::size_t>(ilist)].type))
      throw ParseError(name, fe->header_line, "vertex_indices must have an integer item type");
  }

  // Check every count against what the payload can hold before allocating.
  std::size_t total_records = 0;
  for (const auto& e : elements) total_records += e.count;
  if (binary) {
    std::size_t need = 0;
    for (const auto& e : elements) need += e.count * min_record_size(e);
    if (need > bytes.size() - std::min(bytes.size(), s.offset()))
      throw ParseError(name, 0,
                       "binary PLY: element counts need at least " + std::to_string(need) +
                           " bytes, file has " + std::to_string(bytes.size() - s.offset()) + " (truncated?)");
  } else {
    std::size_t lines = 0;
    for (std::size_t i = s.offset(); i < bytes.size(); ++i) lines += bytes[i] == '\n';
    if (total_records > lines + 1)
      throw ParseError(name, s.line(),
                       "element counts (" + std::to_string(total_records) +
                           " records) exceed the lines left in the file (truncated?)");
  }

  std::vector<double> v, n;
  std::vector<int> tris, poly;
  v.reserve(3 * ve->count);
  if (normals) n.reserve(3 * ve->count);
  if (with_sensors) sensors.reserve(ve->count);
  std::vector<double> rec;
  BinaryReader br(bytes, s.offset(), name, big_endian);
  for (const auto& e : elements) {
    const bool is_v = &e == ve, is_f = &e == fe;
    for (std::size_t r = 0; r < e.count; ++r) {
      rec.assign(e.props.size(), 0.0);
      poly.clear();
      if (!binary) {
        if (!s.next_data_line())
          s.fail("file ends in element '" + e.name + "' after " + std::to_string(r) + " of " +
                 std::to_string(e.count));
      }
      std::size_t tok = 0;
      // Errors inside a record: line number in ascii; line 0 and a byte offset in binary.
      const std::size_t record_at = binary ? br.offset() : 0;
      auto fail_at = [&](const std::string& what, std::size_t byte) {
        if (binary) throw ParseError(name, 0, what + " at byte offset " + std::to_string(byte));
        throw ParseError(name, s.line(), what);
      };
      auto next_value = [&](PlyType t, bool integer_only) -> double {
        if (binary) return br.read(t, e.name.c_str(), r);
        if (tok >= s.tokens().size())
          s.fail(e.name + " " + std::to_string(r) + ": expected more values on the line");
        const std::string_view tk = s.tokens()[tok++];
        if (integer_only || is_integer(t))
          return static_cast<double>(
              s.parse_integer(tk, std::numeric_limits<int>::min(), std::numeric_limits<unsigned>::max()));
        return s.parse_double(tk);
      };
      for (std::size_t k = 0; k < e.props.size(); ++k) {
        const auto& p = e.props[k];
        if (!p.is_list) {
          rec[k] = next_value(p.type, false);
          continue;
        }
        const double cnt = next_value(p.count_type, true);
        if (cnt < 0 || cnt > 1e6)
          fail_at(e.name + " " + std::to_string(r) + ": invalid list length " +
                      std::to_string(static_cast<long long>(cnt)),
                  record_at);
        const auto c = static_cast<std::size_t>(cnt);
        if (binary && c * type_size(p.type) > br.left())
          fail_at(e.name + " " + std::to_string(r) + ": list of " + std::to_string(c) + " items (" +
                      std::to_string(c * type_size(p.type)) + " bytes) runs past the end of the file (" +
                      std::to_string(br.left()) + " bytes left)",
                  br.offset());
        for (std::size_t j = 0; j < c; ++j) {
          const std::size_t item_at = binary ? br.offset() : 0;
          const double val = next_value(p.type, false);
          if (is_f && static_cast<int>(k) == ilist) {
            if (val < 0 || val >= static_cast<double>(ve->count))
              fail_at("face " + std::to_string(r) + ": vertex index " +
                          std::to_string(static_cast<long long>(val)) + " out of range (" +
                          std::to_string(ve->count) + " vertices)",
                      item_at);
            poly.push_back(static_cast<int>(val));
          }
        }
      }
      if (!binary && tok < s.tokens().size())
        s.fail(e.name + " " + std::to_string(r) + ": " + std::to_string(s.tokens().size() - tok) +
               " extra values on the line");
      if (is_v) {
        for (int k : {ix, iy, iz}) {
          const double x = rec[static_cast<std::size_t>(k)];
          if (!std::isfinite(x))
            fail_at("vertex " + std::to_string(r) + ": non-finite coordinate", record_at);
          v.push_back(x);
        }
        if (normals)
          for (int k : {inx, iny, inz}) {
            const double x = rec[static_cast<std::size_t>(k)];
            if (!std::isfinite(x)) fail_at("vertex " + std::to_string(r) + ": non-finite normal", record_at);
            n.push_back(x);
          }
        if (with_sensors) {
          const Point3 sensor{rec[static_cast<std::size_t>(ivx)], rec[static_cast<std::size_t>(ivy)],
                              rec[static_cast<std::size_t>(ivz)]};
          if (!std::isfinite(sensor.x) || !std::isfinite(sensor.y) || !std::isfinite(sensor.z))
            fail_at("vertex " + std::to_string(r) + ": non-finite sensor position (vx vy vz)", record_at);
          sensors.push_back(sensor);
        }
      } else if (is_f) {
        if (poly.size() < 3)
          fail_at("face " + std::to_string(r) + " has " + std::to_string(poly.size()) +
                      " vertices (at least 3 needed)",
                  record_at);
        for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
          tris.push_back(poly[0]);
          tris.push_back(poly[k]);
          tris.push_back(poly[k + 1]);
        }
      }
    }
  }
  TriangleMesh m;
  const auto nv = static_cast<Eigen::Index>(v.size() / 3), nt = static_cast<Eigen::Index>(tris.size() / 3);
  m.V = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(v.data(), nv, 3);
  m.F = Eigen::Map<const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(tris.data(), nt, 3);
  if (normals)
    m.N = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(n.data(), nv, 3);
  else
    m.N.resize(0, 3);
  return m;
}

}  // namespace vitri
