// STL reader (binary and ASCII): parse_stl() of io.hpp. The writer is in mesh_writers.cpp.
//
// An STL file is a triangle soup: every facet lists the coordinates of its three corners, so a vertex
// shared by six facets is written six times. The reader welds corners with exactly the same coordinates
// (compared as doubles, 0.0 and -0.0 equal) into one indexed vertex, in the order of first appearance,
// so that a closed STL solid reads as a closed indexed mesh. Corners that are merely close are left
// apart: a tolerance would merge what the model keeps apart, and exporters write a shared corner with the
// same bits every time. The facet normal is ignored: the corners' order gives the orientation
// (counter-clockwise seen from outside, as the STL definition says), and many exporters write zero
// normals. Triangles whose corners coincide after welding are kept (the callers drop them).
//
// Which encoding: binary when the size is exactly 84 + 50 x (the uint32 count at byte 80). Many binary
// files begin their 80-byte header with the word "solid" (SolidWorks among others), so the first word
// alone never decides. Otherwise ASCII when the text begins with "solid" (after blanks).
//
// Binary layout (little-endian): 80-byte header, uint32 triangle count, then per triangle 50 bytes:
// normal float32[3], three corners float32[3], a uint16 attribute (ignored).

#include "text.hpp"
#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace vitri {

using io_detail::LineScanner;

namespace {

constexpr std::size_t kHeaderBytes = 84;    // 80-byte header and the uint32 triangle count
constexpr std::size_t kTriangleBytes = 50;  // normal, 3 corners (12 float32) and a uint16 attribute

/// Corners welded into indexed vertices: an open-addressing hash table (linear probing) of vertex indices,
/// keyed by the exact coordinates. -0.0 is hashed as 0.0 and the coordinates compared with ==, so the two
/// zeros weld. No NaN reaches it (the parsers refuse non-finite coordinates first).
class Welder {
 public:
  /// `name`: the file, for the error when the vertices outgrow int indices.
  explicit Welder(const std::string& name) : name_(name) { slots_.assign(1024, kEmpty); }

  /// Index of the vertex at (x, y, z), added at the end when new.
  int add(double x, double y, double z) {
    std::size_t s = hash(x, y, z) & (slots_.size() - 1);
    for (;; s = (s + 1) & (slots_.size() - 1)) {
      const std::int32_t i = slots_[s];
      if (i == kEmpty) break;
      const double* v = &v_[3 * static_cast<std::size_t>(i)];
      if (v[0] == x && v[1] == y && v[2] == z) return i;
    }
    const std::size_t n = v_.size() / 3;
    if (n >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      throw ParseError(name_, 0, "more than 2^31 - 1 distinct vertices (the mesh's int indices)");
    slots_[s] = static_cast<std::int32_t>(n);
    v_.insert(v_.end(), {x, y, z});
    if (2 * (n + 1) > slots_.size()) grow();  // at most half full: short probes
    return static_cast<int>(n);
  }

  /// The vertices, x y z each, in the order they were added.
  std::vector<double>& vertices() { return v_; }

 private:
  static constexpr std::int32_t kEmpty = -1;

  static std::uint64_t bits(double d) {
    if (d == 0) d = 0;  // -0.0 hashes as 0.0 (they compare equal)
    std::uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    return b;
  }
  static std::size_t hash(double x, double y, double z) {
    std::uint64_t h = bits(x) * 0x9E3779B97F4A7C15ULL;
    h = (h ^ (h >> 31) ^ bits(y)) * 0xBF58476D1CE4E5B9ULL;
    h = (h ^ (h >> 29) ^ bits(z)) * 0x94D049BB133111EBULL;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }
  void grow() {
    slots_.assign(2 * slots_.size(), kEmpty);
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = 0; i < v_.size() / 3; ++i) {
      std::size_t s = hash(v_[3 * i], v_[3 * i + 1], v_[3 * i + 2]) & mask;
      while (slots_[s] != kEmpty) s = (s + 1) & mask;
      slots_[s] = static_cast<std::int32_t>(i);
    }
  }

  const std::string& name_;
  std::vector<std::int32_t> slots_;  // vertex index or kEmpty; a power of two in size
  std::vector<double> v_;
};

TriangleMesh make_mesh(std::vector<double>& v, const std::vector<int>& f) {
  TriangleMesh m;
  const auto nv = static_cast<Eigen::Index>(v.size() / 3), nt = static_cast<Eigen::Index>(f.size() / 3);
  m.V = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(v.data(), nv, 3);
  m.F = Eigen::Map<const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(f.data(), nt, 3);
  m.N.resize(0, 3);
  return m;
}


TriangleMesh parse_binary(std::string_view bytes, const std::string& name, std::size_t count) {
  if (count == 0) throw ParseError(name, 0, "no triangle (binary STL with a triangle count of 0)");
  std::vector<int> f;
  f.reserve(3 * count);
  Welder w(name);
  for (std::size_t t = 0; t < count; ++t) {
    const char* corners = bytes.data() + kHeaderBytes + kTriangleBytes * t + 12;  // past the normal
    for (int c = 0; c < 3; ++c) {
      double x[3];
      for (int a = 0; a < 3; ++a) {
        x[a] = io_detail::load_little<float>(corners + 12 * c + 4 * a);
        if (!std::isfinite(x[a]))
          throw ParseError(name, 0,
                           "triangle " + std::to_string(t) + ": non-finite coordinate at byte offset " +
                               std::to_string(kHeaderBytes + kTriangleBytes * t + 12 + 12 * c + 4 * a));
      }
      f.push_back(w.add(x[0], x[1], x[2]));
    }
  }
  return make_mesh(w.vertices(), f);
}

/// Whether token t is the keyword kw (lower case), case-insensitively.
bool is(std::string_view t, std::string_view kw) {
  if (t.size() != kw.size()) return false;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(t[i])) != kw[i]) return false;
  return true;
}

/// A token as shown in a message: at most 24 characters, anything unprintable as '?'.
std::string shown(std::string_view t) {
  std::string s(t.substr(0, 24));
  for (char& c : s)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  return t.size() > 24 ? s + "..." : s;
}

/// The tokens of an ASCII STL across lines (any whitespace separates them; a keyword may even end a line
/// and its operands follow on the next), with the line of the last one read for the messages.
class Tokens {
 public:
  Tokens(std::string_view text, const std::string& name) : s_(text, name, /*comments=*/false) {}

  /// The next token; empty at the end of the text (line() is then the last line).
  std::string_view next() {
    while (at_ >= s_.tokens().size()) {
      if (!s_.next_data_line()) return {};
      at_ = 0;
    }
    return s_.tokens()[at_++];
  }
  /// Drops the rest of the current line (the name after `solid` and `endsolid`).
  void skip_line() { at_ = s_.tokens().size(); }
  std::size_t line() const { return s_.line(); }
  [[noreturn]] void fail(const std::string& what) const { s_.fail(what); }

 private:
  LineScanner s_;
  std::size_t at_ = 0;
};

TriangleMesh parse_ascii(std::string_view text, const std::string& name) {
  Tokens in(text, name);
  std::size_t facet = 0;  // 0-based, as the messages count
  // The next token, which must be the keyword kw (`what`: where we are, for the message).
  auto expect = [&](std::string_view kw, const std::string& what) {
    const std::string_view t = in.next();
    if (t.empty()) in.fail("file ends in " + what + " (expected '" + std::string(kw) + "')");
    if (!is(t, kw)) in.fail(what + ": expected '" + std::string(kw) + "', got '" + shown(t) + "'");
  };
  auto number = [&](std::string_view t, const std::string& what, bool finite) {
    if (t.empty()) in.fail("file ends in " + what + " (expected a number)");
    double v = 0;
    const char* b = t.data();
    const char* e = t.data() + t.size();
    if (b != e && *b == '+') ++b;
    const auto r = std::from_chars(b, e, v);
    if (r.ec != std::errc() || r.ptr != e) in.fail(what + ": expected a number, got '" + shown(t) + "'");
    if (finite && !std::isfinite(v)) in.fail(what + ": non-finite coordinate '" + shown(t) + "'");
    return v;
  };
  expect("solid", "the first line");
  in.skip_line();  // the solid's name, if any
  std::vector<int> f;
  Welder w(name);
  for (;;) {
    std::string_view t = in.next();
    if (t.empty()) in.fail("file ends without 'endsolid'");
    if (is(t, "endsolid")) {
      in.skip_line();
      t = in.next();
      if (t.empty()) break;
      if (!is(t, "solid"))  // several solids one after the other are read as one mesh
        in.fail("expected 'solid' or the end of the file after 'endsolid', got '" + shown(t) + "'");
      in.skip_line();
      continue;
    }
    if (!is(t, "facet")) in.fail("expected 'facet' or 'endsolid', got '" + shown(t) + "'");
    const std::string where = "facet " + std::to_string(facet);
    expect("normal", where);
    for (int a = 0; a < 3; ++a) number(in.next(), where + " normal", false);  // ignored (may be NaN)
    expect("outer", where);
    expect("loop", where);
    double x[3][3];
    int corners = 0;
    for (;;) {
      t = in.next();
      if (t.empty()) in.fail("file ends in " + where + " (expected 'vertex' or 'endloop')");
      if (is(t, "endloop")) break;
      if (!is(t, "vertex")) in.fail(where + ": expected 'vertex' or 'endloop', got '" + shown(t) + "'");
      if (corners == 3) in.fail(where + " has more than 3 vertices (STL facets are triangles)");
      for (int a = 0; a < 3; ++a) x[corners][a] = number(in.next(), where + " vertex", true);
      ++corners;
    }
    if (corners != 3)
      in.fail(where + " has " + std::to_string(corners) + " vertices, expected 3 (STL facets are triangles)");
    expect("endfacet", where);
    for (const auto& c : x) f.push_back(w.add(c[0], c[1], c[2]));
    ++facet;
  }
  if (f.empty()) throw ParseError(name, 0, "no triangle (ASCII STL without a facet)");
  return make_mesh(w.vertices(), f);
}

/// Whether the text begins with "solid" (case-insensitive) after blanks.
bool starts_solid(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  return bytes.size() - i >= 5 && is(bytes.substr(i, 5), "solid");
}

}  // namespace

TriangleMesh parse_stl(std::string_view bytes, const std::string& name) {
  std::string not_binary;  // why the bytes are no binary STL
  if (bytes.size() >= kHeaderBytes) {
    const std::uint64_t count = io_detail::load_little<std::uint32_t>(bytes.data() + 80);
    const std::uint64_t expected = kHeaderBytes + kTriangleBytes * count;
    if (bytes.size() == expected) return parse_binary(bytes, name, static_cast<std::size_t>(count));
    not_binary = "the size (" + std::to_string(bytes.size()) + " bytes) does not match a binary STL of " +
                 std::to_string(count) + " triangles (84 + 50 x " + std::to_string(count) + " = " +
                 std::to_string(expected) + " bytes)";
  } else {
    not_binary = "the size (" + std::to_string(bytes.size()) +
                 " bytes) is below a binary STL's 84-byte header and triangle count";
  }
  if (!starts_solid(bytes))
    throw ParseError(name, 0, not_binary + ", and it is not ASCII STL (which begins with 'solid')");
  try {
    return parse_ascii(bytes, name);
  } catch (const ParseError&) {
    // A binary file whose header begins with "solid", cut short or padded: say that rather than what
    // the text reader made of its bytes (text holds no NUL byte; a binary STL's numbers nearly always do).
    if (bytes.size() >= kHeaderBytes && std::memchr(bytes.data(), 0, bytes.size()) != nullptr)
      throw ParseError(name, 0,
                       not_binary +
                           ", and it is not ASCII STL: it begins with 'solid' but holds NUL bytes "
                           "(a binary STL whose header begins with 'solid', truncated or padded?)");
    throw;
  }
}

}  // namespace vitri
