// A strict recursive-descent JSON parser (RFC 8259) and a compact writer. Errors carry the byte offset.
#include "json.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace vitri::studio {
namespace {

const char* type_name(Json::Type t) {
  switch (t) {
    case Json::Type::Null:
      return "null";
    case Json::Type::Bool:
      return "a boolean";
    case Json::Type::Number:
      return "a number";
    case Json::Type::String:
      return "a string";
    case Json::Type::Array:
      return "an array";
    case Json::Type::Object:
      return "an object";
  }
  return "?";
}

/// The character a one-letter escape stands for (\" \\ \/ \b \f \n \r \t), or 0 for another letter.
char simple_escape(char e) {
  constexpr char kFrom[] = "\"\\/bfnrt";
  constexpr char kTo[] = "\"\\/\b\f\n\r\t";
  for (std::size_t k = 0; k + 1 < sizeof kFrom; ++k)
    if (kFrom[k] == e) return kTo[k];
  return 0;
}

/// Parser state: the text and the read position.
class Parser {
 public:
  explicit Parser(std::string_view text) : s_(text) {}

  Json document() {
    Json v = value(0);
    skip_space();
    if (pos_ != s_.size()) fail("unexpected text after the JSON value");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw JsonError("malformed JSON at byte " + std::to_string(pos_) + ": " + what);
  }
  void skip_space() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r'))
      ++pos_;
  }
  bool eat(char c) {
    skip_space();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  void expect_word(std::string_view w) {
    if (s_.substr(pos_, w.size()) != w) fail("unknown literal");
    pos_ += w.size();
  }

  Json value(int depth) {
    if (depth > kMaxJsonDepth) fail("nested deeper than " + std::to_string(kMaxJsonDepth));
    skip_space();
    if (pos_ >= s_.size()) fail("unexpected end of text");
    const char c = s_[pos_];
    if (c == '{') return object(depth);
    if (c == '[') return array(depth);
    if (c == '"') return Json(string());
    if (c == 't') return expect_word("true"), Json(true);
    if (c == 'f') return expect_word("false"), Json(false);
    if (c == 'n') return expect_word("null"), Json();
    if (c == '-' || (c >= '0' && c <= '9')) return Json(number());
    fail(std::string("unexpected character '") + c + "'");
  }

  Json object(int depth) {
    ++pos_;  // '{'
    Json::Object o;
    if (eat('}')) return Json(std::move(o));
    do {
      skip_space();
      if (pos_ >= s_.size() || s_[pos_] != '"') fail("expected a string key");
      std::string key = string();
      if (o.count(key)) fail("duplicate key \"" + key + "\"");
      if (!eat(':')) fail("expected ':'");
      o.emplace(std::move(key), value(depth + 1));
    } while (eat(','));
    if (!eat('}')) fail("expected ',' or '}'");
    return Json(std::move(o));
  }

  Json array(int depth) {
    ++pos_;  // '['
    Json::Array a;
    if (eat(']')) return Json(std::move(a));
    do a.push_back(value(depth + 1));
    while (eat(','));
    if (!eat(']')) fail("expected ',' or ']'");
    return Json(std::move(a));
  }

  double number() {
    // Grammar check first (strtod would accept hex, inf, leading '+', ...).
    const std::size_t start = pos_;
    auto digits = [&] {
      const std::size_t d = pos_;
      while (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') ++pos_;
      return pos_ - d;
    };
    if (s_[pos_] == '-') ++pos_;
    if (pos_ < s_.size() && s_[pos_] == '0')
      ++pos_;
    else if (digits() == 0)
      fail("bad number");
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      if (digits() == 0) fail("bad number: no digit after '.'");
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (digits() == 0) fail("bad number: no digit in the exponent");
    }
    const std::string text(s_.substr(start, pos_ - start));
    const double d = std::strtod(text.c_str(), nullptr);
    if (!std::isfinite(d)) fail("number out of range");
    return d;
  }

  unsigned hex4() {
    if (pos_ + 4 > s_.size()) fail("truncated \\u escape");
    unsigned v = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = s_[pos_++];
      v <<= 4;
      if (c >= '0' && c <= '9')
        v |= static_cast<unsigned>(c - '0');
      else if (c >= 'a' && c <= 'f')
        v |= static_cast<unsigned>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F')
        v |= static_cast<unsigned>(c - 'A' + 10);
      else
        fail("bad \\u escape");
    }
    return v;
  }

  static void append_utf8(std::string& out, unsigned cp) {
    auto byte = [&](unsigned b) { out.push_back(static_cast<char>(b)); };
    if (cp < 0x80)
      byte(cp);
    else if (cp < 0x800)
      byte(0xC0 | (cp >> 6)), byte(0x80 | (cp & 0x3F));
    else if (cp < 0x10000)
      byte(0xE0 | (cp >> 12)), byte(0x80 | ((cp >> 6) & 0x3F)), byte(0x80 | (cp & 0x3F));
    else
      byte(0xF0 | (cp >> 18)), byte(0x80 | ((cp >> 12) & 0x3F)), byte(0x80 | ((cp >> 6) & 0x3F)),
          byte(0x80 | (cp & 0x3F));
  }

  unsigned escaped_code_point() {
    unsigned cp = hex4();
    if (cp >= 0xD800 && cp < 0xDC00) {  // high surrogate: a low one must follow
      if (s_.substr(pos_, 2) != "\\u") fail("lone surrogate in \\u escape");
      pos_ += 2;
      const unsigned lo = hex4();
      if (lo < 0xDC00 || lo >= 0xE000) fail("bad surrogate pair");
      cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
    } else if (cp >= 0xDC00 && cp < 0xE000) {
      fail("lone surrogate in \\u escape");
    }
    return cp;
  }

  std::string string() {
    ++pos_;  // '"'
    std::string out;
    while (true) {
      if (pos_ >= s_.size()) fail("unterminated string");
      const char c = s_[pos_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in string");
      if (c != '\\') {
        out.push_back(c);
        continue;
      }
      if (pos_ >= s_.size()) fail("unterminated string");
      const char e = s_[pos_++];
      if (e == 'u') {
        append_utf8(out, escaped_code_point());
        continue;
      }
      const char c2 = simple_escape(e);
      if (!c2) fail(std::string("bad escape '\\") + e + "'");
      out.push_back(c2);
    }
  }

  std::string_view s_;
  std::size_t pos_ = 0;
};

void dump_to(const Json& v, std::string& out);

}  // namespace

Json Json::parse(std::string_view text) {
  return Parser(text).document();
}

bool Json::as_bool(const std::string& what) const {
  if (type_ != Type::Bool) throw JsonError(what + " must be a boolean, got " + type_name(type_));
  return bool_;
}
double Json::as_number(const std::string& what) const {
  if (type_ != Type::Number) throw JsonError(what + " must be a number, got " + type_name(type_));
  return number_;
}
const std::string& Json::as_string(const std::string& what) const {
  if (type_ != Type::String) throw JsonError(what + " must be a string, got " + type_name(type_));
  return string_;
}
const Json::Array& Json::as_array(const std::string& what) const {
  if (type_ != Type::Array) throw JsonError(what + " must be an array, got " + type_name(type_));
  return array_;
}
const Json::Object& Json::as_object(const std::string& what) const {
  if (type_ != Type::Object) throw JsonError(what + " must be an object, got " + type_name(type_));
  return object_;
}
const Json* Json::find(const std::string& key) const {
  const auto it = object_.find(key);
  return it == object_.end() ? nullptr : &it->second;
}

std::string json_quote(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out.push_back(c);
        }
    }
  }
  return out + "\"";
}

std::string json_number(double d) {
  if (!std::isfinite(d)) throw JsonError("cannot write a non-finite number as JSON");
  char buf[32];
  if (d == std::floor(d) && std::fabs(d) < 1e15)
    std::snprintf(buf, sizeof buf, "%.0f", d);
  else
    std::snprintf(buf, sizeof buf, "%.17g", d);
  return buf;
}

namespace {

void dump_to(const Json& v, std::string& out) {
  switch (v.type()) {
    case Json::Type::Null:
      out += "null";
      return;
    case Json::Type::Bool:
      out += v.as_bool("") ? "true" : "false";
      return;
    case Json::Type::Number:
      out += json_number(v.as_number(""));
      return;
    case Json::Type::String:
      out += json_quote(v.as_string(""));
      return;
    case Json::Type::Array: {
      out.push_back('[');
      bool first = true;
      for (const Json& e : v.as_array("")) {
        if (!first) out.push_back(',');
        first = false;
        dump_to(e, out);
      }
      out.push_back(']');
      return;
    }
    case Json::Type::Object: {
      out.push_back('{');
      bool first = true;
      for (const auto& [k, e] : v.as_object("")) {
        if (!first) out.push_back(',');
        first = false;
        out += json_quote(k);
        out.push_back(':');
        dump_to(e, out);
      }
      out.push_back('}');
      return;
    }
  }
}

}  // namespace

std::string Json::dump() const {
  std::string out;
  dump_to(*this, out);
  return out;
}

}  // namespace vitri::studio
