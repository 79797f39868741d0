#pragma once
// Line- and token-level scanning of text files with line numbers for the error messages.

#include "vitri/core/error.hpp"
#include "vitri/io/io.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <string_view>
#include <vector>

namespace vitri::io_detail {

/// Iterates over the lines of a text, stripping `#` comments (when enabled) and '\r', splitting tokens
/// on blanks. Lines with no token are skipped by next_data_line().
class LineScanner {
 public:
  /// `separators`: characters that separate tokens besides blanks (point files: "," and ";").
  LineScanner(std::string_view text, std::string name, bool comments = true, std::string_view separators = {})
      : text_(text), name_(std::move(name)), comments_(comments) {
    for (const char c : std::string_view(" \t\r\v\f")) separator_[static_cast<unsigned char>(c)] = true;
    for (const char c : separators) separator_[static_cast<unsigned char>(c)] = true;
  }

  /// Advances to the next line holding a token; false at the end of the text.
  bool next_data_line() {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end < text_.size() ? end + 1 : text_.size();
      ++line_no_;
      if (comments_) {
        const std::size_t hash = line.find('#');
        if (hash != std::string_view::npos) line = line.substr(0, hash);
      }
      split(line);
      if (!tokens_.empty()) return true;
    }
    tokens_.clear();
    return false;
  }

  const std::vector<std::string_view>& tokens() const { return tokens_; }
  std::size_t line() const { return line_no_; }
  const std::string& name() const { return name_; }
  /// Byte offset just after the current line (binary payloads start there).
  std::size_t offset() const { return pos_; }

  [[noreturn]] void fail(const std::string& what) const { throw ParseError(name_, line_no_, what); }

  /// Token i as a finite double.
  double number(std::size_t i) const {
    if (i >= tokens_.size())
      fail("expected a number in column " + std::to_string(i + 1) + ", line has " +
           std::to_string(tokens_.size()) + " tokens");
    return parse_double(tokens_[i]);
  }

  double parse_double(std::string_view t) const {
    double v = 0;
    const char* b = t.data();
    const char* e = t.data() + t.size();
    if (b != e && *b == '+') ++b;
    const auto r = std::from_chars(b, e, v);
    if (r.ec != std::errc() || r.ptr != e) fail("not a number: '" + std::string(t) + "'");
    if (!std::isfinite(v)) fail("non-finite number: '" + std::string(t) + "'");
    return v;
  }

  /// Token i as an integer in [lo, hi].
  long long integer(std::size_t i, long long lo, long long hi) const {
    if (i >= tokens_.size()) fail("expected an integer in column " + std::to_string(i + 1));
    return parse_integer(tokens_[i], lo, hi);
  }

  long long parse_integer(std::string_view t, long long lo, long long hi) const {
    long long v = 0;
    const char* b = t.data();
    const char* e = t.data() + t.size();
    if (b != e && *b == '+') ++b;
    const auto r = std::from_chars(b, e, v);
    if (r.ec != std::errc() || r.ptr != e) fail("not an integer: '" + std::string(t) + "'");
    if (v < lo || v > hi)
      fail("integer " + std::to_string(v) + " out of range [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
    return v;
  }

 private:
  void split(std::string_view line) {
    tokens_.clear();
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && separates(line[i])) ++i;
      const std::size_t b = i;
      while (i < line.size() && !separates(line[i])) ++i;
      if (i > b) tokens_.push_back(line.substr(b, i - b));
    }
  }
  bool separates(char c) const { return separator_[static_cast<unsigned char>(c)]; }

  std::string_view text_;
  std::string name_;
  bool comments_;
  std::array<bool, 256> separator_{};  // blanks and the extra separators
  std::size_t pos_ = 0;
  std::size_t line_no_ = 0;
  std::vector<std::string_view> tokens_;
};

/// Reads a whole file; ParseError(path, 0, ...) when it cannot be opened.
std::string slurp(const std::string& path);
/// parse_ply() that also gives the vertices' sensor positions (properties vx vy vz, float or double, when
/// all three are present; `sensors` is left empty otherwise), for read_input()'s PLY point clouds.
TriangleMesh parse_ply_with_sensors(std::string_view bytes, const std::string& name,
                                    std::vector<Point3>& sensors);
/// Opens `path` for writing; ParseError(path, 0, ...) when it cannot be opened.
std::ofstream open_out(const std::string& path, bool binary = false);
/// Flushes; ParseError(path, 0, "write error") when the stream failed.
void finish_out(std::ofstream& out, const std::string& path);
/// Whether this machine stores integers little-endian (binary PLY is read and written in that order).
inline bool host_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}
/// The value of type T (an arithmetic type) stored little-endian at p (unaligned: copied bytewise).
template <class T>
T load_little(const void* p) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, p, sizeof(T));
  if (!host_little_endian())
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  T v;
  std::memcpy(&v, raw, sizeof(T));
  return v;
}
/// Whether the mesh has one normal per vertex (N is #V x 3, and there are vertices).
inline bool has_vertex_normals(const TriangleMesh& m) {
  return m.N.rows() == m.V.rows() && m.N.cols() == 3 && m.V.rows() > 0;
}
/// A double with 17 significant digits (round-trips exactly), locale-independent.
std::string num(double v);

/// Writes v at p as printf's "%.17g" would (std::to_chars with the same format and precision: no locale,
/// no varargs, several times faster); returns the end. p must have room for 32 characters.
inline char* put_number(char* p, double v) {
  return std::to_chars(p, p + 32, v, std::chars_format::general, 17).ptr;
}

/// Text formatted into a buffer and written to the stream in blocks of about 1 MB: the writers' numbers
/// and indices without a stream insertion per token. flush() before checking the stream.
class TextWriter {
 public:
  explicit TextWriter(std::ostream& out) : out_(out) { buf_.resize(kBlock + kSlack); }
  TextWriter(const TextWriter&) = delete;
  TextWriter& operator=(const TextWriter&) = delete;

  TextWriter& number(double v) {
    pos_ = static_cast<std::size_t>(put_number(buf_.data() + pos_, v) - buf_.data());
    return after_token();
  }
  TextWriter& integer(long long v) {
    pos_ = static_cast<std::size_t>(std::to_chars(buf_.data() + pos_, buf_.data() + pos_ + 24, v).ptr - buf_.data());
    return after_token();
  }
  TextWriter& put(char c) {
    buf_[pos_++] = c;
    return after_token();
  }
  /// Short literal text (below kSlack characters).
  TextWriter& text(std::string_view t) {
    std::memcpy(buf_.data() + pos_, t.data(), t.size());
    pos_ += t.size();
    return after_token();
  }
  void flush() {
    out_.write(buf_.data(), static_cast<std::streamsize>(pos_));
    pos_ = 0;
  }

 private:
  static constexpr std::size_t kBlock = std::size_t(1) << 20;
  static constexpr std::size_t kSlack = 64;  // room for one more token past the block
  TextWriter& after_token() {
    if (pos_ >= kBlock) flush();
    return *this;
  }
  std::ostream& out_;
  std::vector<char> buf_;
  std::size_t pos_ = 0;
};

}  // namespace vitri::io_detail
