#pragma once
// A small, strict JSON value with a parser and a writer, for the studio's HTTP API (RFC 8259: no
// comments, no trailing commas, no NaN/Infinity, no duplicate object keys, UTF-8 passed through,
// \uXXXX escapes decoded). Numbers are doubles. Nesting is limited to kMaxJsonDepth.
#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace vitri::studio {

/// Bad JSON text, or a JSON value of the wrong shape; `what()` says what and where (byte offset or key).
class JsonError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Deepest nesting of arrays and objects the parser accepts.
inline constexpr int kMaxJsonDepth = 32;

/// One JSON value.
class Json {
 public:
  enum class Type { Null, Bool, Number, String, Array, Object };
  using Array = std::vector<Json>;
  using Object = std::map<std::string, Json>;

  Json() = default;
  Json(bool b) : type_(Type::Bool), bool_(b) {}  // NOLINT: implicit on purpose (literals)
  Json(double d) : type_(Type::Number), number_(d) {}
  Json(int i) : type_(Type::Number), number_(i) {}
  Json(std::size_t n) : type_(Type::Number), number_(static_cast<double>(n)) {}
  Json(const char* s) : type_(Type::String), string_(s) {}
  Json(std::string s) : type_(Type::String), string_(std::move(s)) {}
  Json(Array a) : type_(Type::Array), array_(std::move(a)) {}
  Json(Object o) : type_(Type::Object), object_(std::move(o)) {}

  /// Parses a whole document (surrounding white space allowed). @throws JsonError with the byte offset.
  static Json parse(std::string_view text);
  /// Compact text; numbers with 17 significant digits (round trip). @throws JsonError for a non-finite
  /// number.
  std::string dump() const;

  Type type() const { return type_; }
  bool is_null() const { return type_ == Type::Null; }
  // Typed access: @throws JsonError naming `what` when the value has another type.
  bool as_bool(const std::string& what) const;
  double as_number(const std::string& what) const;
  const std::string& as_string(const std::string& what) const;
  const Array& as_array(const std::string& what) const;
  const Object& as_object(const std::string& what) const;
  /// Member `key` of an object, or nullptr when absent. @pre is an object.
  const Json* find(const std::string& key) const;

 private:
  Type type_ = Type::Null;
  bool bool_ = false;
  double number_ = 0;
  std::string string_;
  Array array_;
  Object object_;
};

/// `s` as a JSON string literal, quotes included.
std::string json_quote(std::string_view s);
/// A finite double as JSON (17 significant digits; integers without exponent when exact).
std::string json_number(double d);

}  // namespace vitri::studio
