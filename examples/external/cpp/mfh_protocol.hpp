// mfh_protocol.hpp: mfh's external protocol (versions 1 and 2) for a model written in C++17.
// Header only, no dependency beyond the standard library. A model gives its functions, one item
// at a time; `mfh::serve` does the rest: the JSON-lines framing, describe and version
// negotiation, decoding the request arrays, calling the model, encoding the answers, shutdown.
//
// The protocol (docs/external-protocol.md in the mfh repository), as this file implements it:
//
// - One JSON object per line each way, on stdin / stdout; stdout is the protocol channel, so a
//   model logs to stderr only. Every request carries "v" (version), "id" and "op"; every answer
//   carries the same "id" and either its result or {"error": "..."}.
// - mfh's first request is a version-1 line `{"v":1,"id":0,"op":"describe","versions":[1,2]}`;
//   the answer `{"protocol":V,"name":...,"capabilities":[...],"parameters":{...},...}` chooses
//   the version V of every later request (the newest both sides speak, at most `max_version`).
//   The capabilities are the ops whose callback the Model sets (below); more fields of the
//   describe answer (a float32 model's "precision":"f32", a BSDF's "eta") go in
//   `Model::describe_extra`.
// - Version 1: arrays are JSON arrays, [[x,y,z],...] for directions, [[u1,u2],...] for uniform
//   pairs, [v,...] for values; non-finite answers are the bare tokens Infinity / -Infinity.
// - Version 2: each array is one string, base64 (standard alphabet, padded) of little-endian
//   IEEE-754 f64, row-major; requests also carry "n", the item count. This file reads both
//   forms in version 2 (a hand-typed request may use JSON arrays) and answers in base64.
// - Requests hold at most 65 536 items; "shutdown" (or the end of stdin) ends the loop.
//
// Errors are answers, never crashes: a line that is not strict JSON (RFC 8259, plus the tokens
// NaN, Infinity and -Infinity that version 1 allows), an unknown op, a missing or ill-shaped
// array, invalid base64, a byte count that is not a whole number of items, arrays of different
// lengths or an "n" that disagrees, and an exception thrown by the model each answer
// {"id":..., "error":"..."} naming the field and what was wrong (an unparsable line has no id:
// "id":null). mfh then reports the error with the request and ends the child.
//
// Use (see ggx_float.cpp beside this file):
//
//     mfh::Model model;
//     model.name = "my_ggx";
//     model.parameters = mfh::Json::object({{"family", "ggx"}, {"alpha", 0.3}});
//     model.describe_extra = {{"precision", "f32"}};
//     model.d = [&](const mfh::Vec3& m) { return my_d(m); };
//     ...
//     return mfh::serve(model);            // reads std::cin, writes std::cout
//
// Written from the protocol document; the reader and writer cover what the protocol's messages
// need (objects, arrays, strings with every escape, numbers, true/false/null), strictly.

#ifndef MFH_PROTOCOL_HPP
#define MFH_PROTOCOL_HPP

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

namespace mfh {

/// A direction (unit vector, local frame, macro-normal +z).
using Vec3 = std::array<double, 3>;
/// A uniform pair in [0, 1)^2.
using Pair = std::array<double, 2>;
/// A uniform triple in [0, 1)^3 (bsdf_sample: u0 chooses the lobe).
using Triple = std::array<double, 3>;

/// The protocol versions this file speaks, oldest first.
inline constexpr int kVersions[] = {1, 2};
/// The most items in one request (the protocol's limit).
inline constexpr std::size_t kMaxItems = 65536;
/// The most bytes of one request line read (mfh's requests are at most ~2.8 MB; the protocol's
/// line limit is 64 MiB).
inline constexpr std::size_t kMaxLineBytes = 64u << 20;
/// The deepest nesting of arrays and objects the reader accepts (the protocol's messages need
/// 3: the answer object, an array of directions, a direction).
inline constexpr int kMaxDepth = 64;

/// A malformed line or request: the message names the field and what is wrong.
struct ProtocolError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// ------------------------------------------------------------------------------------------
// JSON values
// ------------------------------------------------------------------------------------------

/// A JSON value: null, a boolean, a number (f64), a string, an array or an object (members in
/// order; the reader refuses duplicate keys).
class Json {
 public:
  enum class Type { Null, Bool, Number, String, Array, Object };
  using Members = std::vector<std::pair<std::string, Json>>;

  Json() = default;
  Json(std::nullptr_t) {}
  Json(bool b) : type_(Type::Bool), bool_(b) {}
  template <class T, class = std::enable_if_t<std::is_arithmetic_v<T> && !std::is_same_v<T, bool>>>
  Json(T x) : type_(Type::Number), number_(static_cast<double>(x)) {}
  Json(const char* s) : type_(Type::String), string_(s) {}
  Json(std::string s) : type_(Type::String), string_(std::move(s)) {}

  static Json array(std::vector<Json> items = {}) {
    Json j;
    j.type_ = Type::Array;
    j.array_ = std::move(items);
    return j;
  }
  static Json object(Members members = {}) {
    Json j;
    j.type_ = Type::Object;
    j.object_ = std::move(members);
    return j;
  }

  Type type() const { return type_; }
  bool is_null() const { return type_ == Type::Null; }
  bool is_number() const { return type_ == Type::Number; }
  bool is_string() const { return type_ == Type::String; }
  bool is_array() const { return type_ == Type::Array; }
  bool is_object() const { return type_ == Type::Object; }

  bool as_bool() const { return expect(Type::Bool), bool_; }
  double as_number() const { return expect(Type::Number), number_; }
  const std::string& as_string() const { return expect(Type::String), string_; }
  const std::vector<Json>& as_array() const { return expect(Type::Array), array_; }
  std::vector<Json>& as_array() { return expect(Type::Array), array_; }
  const Members& members() const { return expect(Type::Object), object_; }

  /// The member `key` of an object, or nullptr.
  const Json* find(std::string_view key) const {
    expect(Type::Object);
    for (const auto& [k, v] : object_)
      if (k == key) return &v;
    return nullptr;
  }
  /// Adds (or replaces) member `key` of an object.
  void set(std::string key, Json value) {
    expect(Type::Object);
    for (auto& [k, v] : object_)
      if (k == key) {
        v = std::move(value);
        return;
      }
    object_.emplace_back(std::move(key), std::move(value));
  }

  static const char* type_name(Type t) {
    switch (t) {
      case Type::Null: return "null";
      case Type::Bool: return "a boolean";
      case Type::Number: return "a number";
      case Type::String: return "a string";
      case Type::Array: return "an array";
      case Type::Object: return "an object";
    }
    return "?";
  }

 private:
  void expect(Type t) const {
    if (type_ != t)
      throw ProtocolError(std::string("expected ") + type_name(t) + ", found " + type_name(type_));
  }

  Type type_ = Type::Null;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<Json> array_;
  Members object_;
};

namespace detail {

/// The length of the valid UTF-8 sequence starting at s[pos] (a byte >= 0x80), or 0: no
/// overlong forms, no surrogates, nothing above U+10FFFF.
inline std::size_t utf8_length(std::string_view s, std::size_t pos) {
  auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[pos + k]); };
  unsigned char b = byte(0);
  std::size_t n = b >= 0xF0 && b <= 0xF4 ? 4 : b >= 0xE0 && b <= 0xEF ? 3 : b >= 0xC2 && b <= 0xDF ? 2 : 0;
  if (n == 0 || pos + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(k) & 0xC0) != 0x80) return 0;
  std::uint32_t cp = n == 2 ? (b & 0x1Fu) : n == 3 ? (b & 0x0Fu) : (b & 0x07u);
  for (std::size_t k = 1; k < n; ++k) cp = (cp << 6) | (byte(k) & 0x3Fu);
  bool overlong = (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000);
  if (overlong || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

/// `text` with every byte outside printable ASCII written as \xHH: safe to quote in an error
/// message whatever the input held.
inline std::string printable(std::string_view text) {
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (char ch : text) {
    unsigned char c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7F) {
      out += ch;
    } else {
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

/// A strict recursive-descent JSON reader over one line. Errors name the byte offset.
class Reader {
 public:
  explicit Reader(std::string_view text) : s_(text) {}

  Json document() {
    skip_space();
    Json v = value(0);
    skip_space();
    if (pos_ != s_.size()) fail("unexpected text after the JSON value");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    std::string near = printable(s_.substr(pos_, 24));
    throw ProtocolError("invalid JSON at byte " + std::to_string(pos_) + ": " + what +
                        (pos_ < s_.size() ? " (near \"" + near + "\")" : " (at the end of the line)"));
  }
  void skip_space() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\r' || s_[pos_] == '\n'))
      ++pos_;
  }
  bool literal(std::string_view word) {
    if (s_.substr(pos_, word.size()) != word) return false;
    pos_ += word.size();
    return true;
  }

  Json value(int depth) {
    if (pos_ >= s_.size()) fail("a value is missing");
    char c = s_[pos_];
    if (c == '{') return object(depth + 1);
    if (c == '[') return array(depth + 1);
    if (c == '"') return Json(string());
    if (literal("true")) return Json(true);
    if (literal("false")) return Json(false);
    if (literal("null")) return Json(nullptr);
    // Version 1's non-finite tokens (what Python's json.dumps writes).
    if (literal("NaN")) return Json(std::numeric_limits<double>::quiet_NaN());
    if (literal("Infinity")) return Json(std::numeric_limits<double>::infinity());
    if (literal("-Infinity")) return Json(-std::numeric_limits<double>::infinity());
    if (c == '-' || (c >= '0' && c <= '9')) return Json(number());
    fail("unexpected character '" + printable(std::string_view(&c, 1)) + "'");
  }

  Json object(int depth) {
    if (depth > kMaxDepth) fail("nested deeper than " + std::to_string(kMaxDepth));
    ++pos_;  // '{'
    Json out = Json::object();
    skip_space();
    if (pos_ < s_.size() && s_[pos_] == '}') {
      ++pos_;
      return out;
    }
    while (true) {
      skip_space();
      if (pos_ >= s_.size() || s_[pos_] != '"') fail("expected a key (a string)");
      std::size_t key_at = pos_;
      std::string key = string();
      if (out.find(key) != nullptr) {
        pos_ = key_at;
        fail("duplicate key \"" + key + "\"");
      }
      skip_space();
      if (pos_ >= s_.size() || s_[pos_] != ':') fail("expected ':' after a key");
      ++pos_;
      skip_space();
      Json v = value(depth);
      out.set(std::move(key), std::move(v));
      skip_space();
      if (pos_ < s_.size() && s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (pos_ < s_.size() && s_[pos_] == '}') {
        ++pos_;
        return out;
      }
      fail("expected ',' or '}' in an object");
    }
  }

  Json array(int depth) {
    if (depth > kMaxDepth) fail("nested deeper than " + std::to_string(kMaxDepth));
    ++pos_;  // '['
    std::vector<Json> items;
    skip_space();
    if (pos_ < s_.size() && s_[pos_] == ']') {
      ++pos_;
      return Json::array(std::move(items));
    }
    while (true) {
      skip_space();
      items.push_back(value(depth));
      skip_space();
      if (pos_ < s_.size() && s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (pos_ < s_.size() && s_[pos_] == ']') {
        ++pos_;
        return Json::array(std::move(items));
      }
      fail("expected ',' or ']' in an array");
    }
  }

  static void put_utf8(std::string& out, std::uint32_t cp) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  std::uint32_t hex4() {
    if (pos_ + 4 > s_.size()) fail("a \\u escape needs 4 hex digits");
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) {
      char c = s_[pos_++];
      v <<= 4;
      if (c >= '0' && c <= '9') v |= static_cast<std::uint32_t>(c - '0');
      else if (c >= 'a' && c <= 'f') v |= static_cast<std::uint32_t>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F') v |= static_cast<std::uint32_t>(c - 'A' + 10);
      else {
        --pos_;
        fail("a \\u escape needs 4 hex digits");
      }
    }
    return v;
  }

  std::string string() {
    ++pos_;  // '"'
    std::string out;
    while (true) {
      // The plain run up to the next quote, escape, control or non-ASCII byte, copied at once
      // (a version-2 array is megabytes of base64).
      std::size_t start = pos_;
      while (pos_ < s_.size()) {
        unsigned char c = static_cast<unsigned char>(s_[pos_]);
        if (c == '"' || c == '\\' || c < 0x20 || c >= 0x80) break;
        ++pos_;
      }
      out.append(s_.data() + start, pos_ - start);
      if (pos_ >= s_.size()) fail("unterminated string");
      unsigned char c = static_cast<unsigned char>(s_[pos_]);
      if (c == '"') {
        ++pos_;
        return out;
      }
      if (c < 0x20) fail("a control character inside a string (escape it)");
      if (c >= 0x80) {
        std::size_t n = utf8_length(s_, pos_);
        if (n == 0) fail("invalid UTF-8 inside a string");
        out.append(s_.data() + pos_, n);
        pos_ += n;
        continue;
      }
      ++pos_;  // '\\'
      if (pos_ >= s_.size()) fail("unterminated escape");
      char e = s_[pos_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          std::uint32_t cp = hex4();
          if (cp >= 0xDC00 && cp <= 0xDFFF) fail("a lone low surrogate in a \\u escape");
          if (cp >= 0xD800 && cp <= 0xDBFF) {
            if (!literal("\\u")) fail("a high surrogate without its low surrogate");
            std::uint32_t low = hex4();
            if (low < 0xDC00 || low > 0xDFFF) fail("a high surrogate without its low surrogate");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
          }
          put_utf8(out, cp);
          break;
        }
        default:
          --pos_;
          fail(std::string("unknown escape '\\") + e + "'");
      }
    }
  }

  double number() {
    // The grammar of RFC 8259: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
    std::size_t start = pos_;
    auto digit = [&] { return pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9'; };
    if (s_[pos_] == '-') ++pos_;
    if (!digit()) fail("a digit is missing in a number");
    if (s_[pos_] == '0') {
      ++pos_;
      if (digit()) fail("a number with a leading zero");
    } else {
      while (digit()) ++pos_;
    }
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      if (!digit()) fail("a digit is missing after '.'");
      while (digit()) ++pos_;
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (!digit()) fail("a digit is missing in an exponent");
      while (digit()) ++pos_;
    }
    return parse_double(s_.substr(start, pos_ - start));
  }

 public:
  /// The f64 nearest to a number already checked against the grammar (correctly rounded;
  /// beyond the f64 range: ±infinity, as strtod).
  static double parse_double(std::string_view text) {
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
    double x = 0.0;
    auto r = std::from_chars(text.data(), text.data() + text.size(), x);
    if (r.ec == std::errc()) return x;
#endif
    // Fallback (and out-of-range numbers): strtod in the "C" locale, which the program has
    // unless it called setlocale.
    std::string copy(text);
    return std::strtod(copy.c_str(), nullptr);
  }

 private:
  std::string_view s_;
  std::size_t pos_ = 0;
};

/// Appends the shortest decimal text that reads back as exactly `x`; non-finite numbers as the
/// tokens Infinity, -Infinity, NaN (protocol version 1).
inline void write_number(std::string& out, double x) {
  if (std::isnan(x)) {
    out += "NaN";
    return;
  }
  if (std::isinf(x)) {
    out += x > 0 ? "Infinity" : "-Infinity";
    return;
  }
  char buf[40];
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
  auto r = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, r.ptr);
#else
  int n = std::snprintf(buf, sizeof buf, "%.17g", x);
  out.append(buf, static_cast<std::size_t>(n));
#endif
}

/// Appends `s` as a JSON string; bytes that are not valid UTF-8 become U+FFFD, so that the
/// line stays valid JSON whatever a model's name or exception message holds.
inline void write_string(std::string& out, std::string_view s) {
  static const char* hex = "0123456789abcdef";
  out += '"';
  for (std::size_t i = 0; i < s.size(); ++i) {
    char ch = s[i];
    unsigned char c = static_cast<unsigned char>(ch);
    if (c >= 0x80) {
      std::size_t n = utf8_length(s, i);
      if (n == 0) {
        out += "\\ufffd";
      } else {
        out.append(s.data() + i, n);
        i += n - 1;
      }
      continue;
    }
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20) {
          out += "\\u00";
          out += hex[c >> 4];
          out += hex[c & 15];
        } else {
          out += ch;
        }
    }
  }
  out += '"';
}

inline void write(std::string& out, const Json& v) {
  switch (v.type()) {
    case Json::Type::Null: out += "null"; break;
    case Json::Type::Bool: out += v.as_bool() ? "true" : "false"; break;
    case Json::Type::Number: write_number(out, v.as_number()); break;
    case Json::Type::String: write_string(out, v.as_string()); break;
    case Json::Type::Array: {
      out += '[';
      bool first = true;
      for (const Json& item : v.as_array()) {
        if (!first) out += ',';
        first = false;
        write(out, item);
      }
      out += ']';
      break;
    }
    case Json::Type::Object: {
      out += '{';
      bool first = true;
      for (const auto& [key, item] : v.members()) {
        if (!first) out += ',';
        first = false;
        write_string(out, key);
        out += ':';
        write(out, item);
      }
      out += '}';
      break;
    }
  }
}

}  // namespace detail

/// Parses one JSON text strictly (the whole of `text`); throws ProtocolError naming the byte.
inline Json parse_json(std::string_view text) { return detail::Reader(text).document(); }

/// The compact JSON text of `v` (no newline).
inline std::string to_json(const Json& v) {
  std::string out;
  detail::write(out, v);
  return out;
}

// ------------------------------------------------------------------------------------------
// Base64 of little-endian f64 (version 2)
// ------------------------------------------------------------------------------------------

/// Base64 (standard alphabet, padded) of the numbers as little-endian IEEE-754 f64, whatever
/// the host's byte order.
inline std::string base64_encode_f64(const std::vector<double>& numbers) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> bytes(8 * numbers.size());
  for (std::size_t i = 0; i < numbers.size(); ++i) {
    std::uint64_t bits;
    std::memcpy(&bits, &numbers[i], 8);
    for (int k = 0; k < 8; ++k) bytes[8 * i + k] = static_cast<unsigned char>(bits >> (8 * k));
  }
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    std::uint32_t t = (std::uint32_t(bytes[i]) << 16) | (std::uint32_t(bytes[i + 1]) << 8) | bytes[i + 2];
    out += alphabet[t >> 18];
    out += alphabet[(t >> 12) & 63];
    out += alphabet[(t >> 6) & 63];
    out += alphabet[t & 63];
  }
  std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t t = std::uint32_t(bytes[i]) << 16;
    if (rest == 2) t |= std::uint32_t(bytes[i + 1]) << 8;
    out += alphabet[t >> 18];
    out += alphabet[(t >> 12) & 63];
    out += rest == 2 ? alphabet[(t >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

/// The f64 numbers of a base64 string (standard alphabet, padded, no whitespace) of
/// little-endian f64; throws ProtocolError saying what is wrong (a bad character and where,
/// a length that is not a multiple of 4, a byte count that is not a multiple of 8).
inline std::vector<double> base64_decode_f64(std::string_view text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  if (text.size() % 4 != 0)
    throw ProtocolError("invalid base64: " + std::to_string(text.size()) +
                        " characters, not a multiple of 4 (standard base64 is padded with '=')");
  std::size_t pad = 0;
  if (!text.empty() && text.back() == '=') pad = text.size() >= 2 && text[text.size() - 2] == '=' ? 2 : 1;
  std::vector<unsigned char> bytes;
  bytes.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    std::uint32_t t = 0;
    bool last = i + 4 == text.size();
    for (std::size_t k = 0; k < 4; ++k) {
      char c = text[i + k];
      int v = value(c);
      if (v < 0) {
        bool padding = last && c == '=' && k >= 4 - pad;
        if (!padding)
          throw ProtocolError("invalid base64: character '" + detail::printable(std::string_view(&c, 1)) + "' at " +
                              std::to_string(i + k) + " (standard alphabet A-Z a-z 0-9 + /, '=' only at the end)");
        v = 0;
      }
      t = (t << 6) | static_cast<std::uint32_t>(v);
    }
    std::size_t keep = last ? 3 - pad : 3;
    for (std::size_t k = 0; k < keep; ++k) bytes.push_back(static_cast<unsigned char>(t >> (16 - 8 * k)));
  }
  if (bytes.size() % 8 != 0)
    throw ProtocolError(std::to_string(bytes.size()) +
                        " bytes of base64-decoded data, not a whole number of little-endian f64 (8 bytes each)");
  std::vector<double> out(bytes.size() / 8);
  for (std::size_t i = 0; i < out.size(); ++i) {
    std::uint64_t bits = 0;
    for (int k = 0; k < 8; ++k) bits |= std::uint64_t(bytes[8 * i + k]) << (8 * k);
    std::memcpy(&out[i], &bits, 8);
  }
  return out;
}

// ------------------------------------------------------------------------------------------
// The model and the server
// ------------------------------------------------------------------------------------------

/// The two forms of G2 (seed 001 eq 22 / 23).
enum class Masking { Uncorrelated, HeightCorrelated };

/// What bsdf_sample answers for one item (a failed sample: pdf 0, weight 0, any finite wo).
struct BsdfSample {
  Vec3 wo;
  double pdf;
  double weight;
};

/// A model: its describe fields and one callback per capability, each taking one item. A
/// callback left empty is a capability not offered. What each op means (and what mfh assumes
/// when an optional one is missing) is docs/external-protocol.md, "Requests and answers".
struct Model {
  std::string name;
  Json parameters = Json::object();
  /// More fields of the describe answer, e.g. {"precision", "f32"} for a float32 model.
  Json::Members describe_extra;

  std::function<double(const Vec3& m)> d;
  std::function<double(const Vec3& w)> lambda;
  std::function<double(const Vec3& w, const Vec3& m)> g1;
  std::function<double(const Vec3& wo, const Vec3& wi, const Vec3& m, Masking masking)> g2;
  std::function<Vec3(const Pair& u)> sample_wm;
  std::function<double(const Vec3& m)> pdf_wm;
  std::function<Vec3(const Vec3& wi, const Pair& u)> sample_wm_visible;
  std::function<double(const Vec3& wi, const Vec3& m)> pdf_wm_visible;
  std::function<double(const Vec3& wi, const Vec3& wo)> bsdf_eval;
  std::function<double(const Vec3& wi, const Vec3& wo)> bsdf_pdf;
  std::function<BsdfSample(const Vec3& wi, const Triple& u)> bsdf_sample;

  /// The capabilities declared in describe: the ops whose callback is set, in protocol order.
  std::vector<std::string> capabilities() const {
    std::vector<std::string> out;
    auto add = [&](bool set, const char* op) {
      if (set) out.emplace_back(op);
    };
    add(bool(d), "d");
    add(bool(lambda), "lambda");
    add(bool(g1), "g1");
    add(bool(g2), "g2");
    add(bool(sample_wm), "sample_wm");
    add(bool(pdf_wm), "pdf_wm");
    add(bool(sample_wm_visible), "sample_wm_visible");
    add(bool(pdf_wm_visible), "pdf_wm_visible");
    add(bool(bsdf_eval), "bsdf_eval");
    add(bool(bsdf_pdf), "bsdf_pdf");
    add(bool(bsdf_sample), "bsdf_sample");
    return out;
  }
};

/// The protocol state of one connection: answers request lines one at a time. `serve` runs it
/// over stdin / stdout; a test may call `answer` directly.
class Server {
 public:
  /// `max_version`: the newest version to accept (2; 1 to debug version 1).
  explicit Server(Model model, int max_version = 2)
      : model_(std::move(model)), max_version_(max_version) {}

  /// The negotiated version (1 until describe chose another).
  int version() const { return version_; }

  /// The answer line (without newline) to one request line; sets `stop` (and answers "")
  /// on shutdown.
  std::string answer(std::string_view line, bool& stop) {
    stop = false;
    Json id;  // null until the request's id is read
    try {
      Json request = parse_json(line);
      if (!request.is_object()) throw ProtocolError("a request must be a JSON object");
      if (const Json* i = request.find("id")) id = *i;
      if (!id.is_number() || id.as_number() < 0 || id.as_number() != std::floor(id.as_number()))
        throw ProtocolError("\"id\" must be a non-negative integer");
      const Json* op = request.find("op");
      if (op == nullptr || !op->is_string()) throw ProtocolError("\"op\" (a string) is missing");
      const std::string& name = op->as_string();
      if (name == "shutdown") {
        stop = true;
        return "";
      }
      Json reply = name == "describe" ? describe(request) : dispatch(name, request);
      Json line_out = Json::object({{"id", id}});
      for (auto& [k, v] : reply.members()) line_out.set(k, v);
      return to_json(line_out);
    } catch (const std::exception& e) {
      return to_json(Json::object({{"id", id}, {"error", std::string(e.what())}}));
    }
  }

 private:
  Json describe(const Json& request) {
    int chosen = 1;
    if (const Json* offered = request.find("versions")) {
      if (!offered->is_array()) throw ProtocolError("\"versions\" must be an array of integers");
      for (const Json& v : offered->as_array()) {
        if (!v.is_number()) throw ProtocolError("\"versions\" must be an array of integers");
        double x = v.as_number();
        for (int known : kVersions)
          if (x == known && known <= max_version_ && known > chosen) chosen = known;
      }
    }
    version_ = chosen;
    std::vector<Json> caps;
    for (const std::string& c : model_.capabilities()) caps.emplace_back(c);
    Json out = Json::object({{"protocol", chosen},
                             {"name", model_.name},
                             {"capabilities", Json::array(std::move(caps))},
                             {"parameters", model_.parameters}});
    for (const auto& [k, v] : model_.describe_extra) out.set(k, v);
    return out;
  }

  /// The numbers of request array `field`, `width` per item: base64 in version 2, or a JSON
  /// array of items (of `width` numbers each, or of numbers when width is 1).
  std::vector<double> numbers(const Json& request, const char* field, std::size_t width) const {
    const Json* v = request.find(field);
    if (v == nullptr) throw ProtocolError(std::string("the request has no \"") + field + "\" array");
    std::vector<double> out;
    if (v->is_string()) {
      if (version_ < 2)
        throw ProtocolError(std::string("\"") + field +
                            "\" is a string (base64), which is version 2; this connection speaks version 1");
      try {
        out = base64_decode_f64(v->as_string());
      } catch (const ProtocolError& e) {
        throw ProtocolError(std::string("\"") + field + "\": " + e.what());
      }
      if (out.size() % width != 0)
        throw ProtocolError(std::string("\"") + field + "\": " + std::to_string(out.size()) +
                            " numbers, not a whole number of items of " + std::to_string(width));
    } else if (v->is_array()) {
      const auto& items = v->as_array();
      out.reserve(items.size() * width);
      for (std::size_t i = 0; i < items.size(); ++i) {
        auto bad = [&](const std::string& why) {
          return ProtocolError(std::string("\"") + field + "\" item " + std::to_string(i) + ": " + why);
        };
        if (width == 1) {
          if (!items[i].is_number()) throw bad("not a number");
          out.push_back(items[i].as_number());
          continue;
        }
        if (!items[i].is_array() || items[i].as_array().size() != width)
          throw bad("not an array of " + std::to_string(width) + " numbers");
        for (const Json& x : items[i].as_array()) {
          if (!x.is_number()) throw bad("not an array of " + std::to_string(width) + " numbers");
          out.push_back(x.as_number());
        }
      }
    } else {
      throw ProtocolError(std::string("\"") + field + "\" must be " +
                          (version_ < 2 ? "a JSON array" : "a base64 string or a JSON array"));
    }
    if (out.size() / width > kMaxItems)
      throw ProtocolError(std::string("\"") + field + "\" holds " + std::to_string(out.size() / width) +
                          " items; a request holds at most " + std::to_string(kMaxItems));
    return out;
  }

  /// The common item count of the request's arrays (and its "n" in version 2).
  std::size_t count(const Json& request, const std::vector<std::pair<const char*, std::size_t>>& arrays,
                    const std::vector<const std::vector<double>*>& data) const {
    std::size_t n = data[0]->size() / arrays[0].second;
    for (std::size_t k = 1; k < data.size(); ++k) {
      std::size_t nk = data[k]->size() / arrays[k].second;
      if (nk != n)
        throw ProtocolError(std::string("\"") + arrays[0].first + "\" has " + std::to_string(n) +
                            " items but \"" + arrays[k].first + "\" has " + std::to_string(nk));
    }
    const Json* given = request.find("n");
    if (given == nullptr && version_ >= 2) throw ProtocolError("a version-2 request carries \"n\", the item count");
    if (given != nullptr && (!given->is_number() || given->as_number() != static_cast<double>(n)))
      throw ProtocolError("\"n\" is " + to_json(*given) + " but the arrays hold " + std::to_string(n) + " items");
    return n;
  }

  /// Encodes an answer array: base64 in version 2, a JSON array in version 1.
  Json encode(const std::vector<double>& numbers, std::size_t width) const {
    if (version_ >= 2) return Json(base64_encode_f64(numbers));
    std::vector<Json> items;
    items.reserve(numbers.size() / width);
    for (std::size_t i = 0; i < numbers.size(); i += width) {
      if (width == 1) {
        items.emplace_back(numbers[i]);
        continue;
      }
      std::vector<Json> item(numbers.begin() + static_cast<std::ptrdiff_t>(i),
                             numbers.begin() + static_cast<std::ptrdiff_t>(i + width));
      items.push_back(Json::array(std::move(item)));
    }
    return Json::array(std::move(items));
  }

  Json dispatch(const std::string& op, const Json& request) {
    if (const Json* v = request.find("v")) {
      if (!v->is_number() || v->as_number() != version_)
        throw ProtocolError("the request's \"v\" is " + to_json(*v) + " but describe chose version " +
                            std::to_string(version_));
    } else {
      throw ProtocolError("\"v\" (the protocol version) is missing");
    }
    auto missing = [&](bool set) {
      if (!set) throw ProtocolError("unknown op \"" + op + "\" (not among this model's capabilities)");
    };
    // The named arrays of the request, checked to hold the same number of items.
    struct Arrays {
      std::vector<std::vector<double>> data;
      std::size_t n;
    };
    auto items = [&](std::vector<std::pair<const char*, std::size_t>> arrays) {
      Arrays r;
      for (auto& [field, width] : arrays) r.data.push_back(numbers(request, field, width));
      std::vector<const std::vector<double>*> views;
      for (auto& d : r.data) views.push_back(&d);
      r.n = count(request, arrays, views);
      return r;
    };
    auto vec3 = [](const std::vector<double>& a, std::size_t i) { return Vec3{a[3 * i], a[3 * i + 1], a[3 * i + 2]}; };
    auto pair = [](const std::vector<double>& a, std::size_t i) { return Pair{a[2 * i], a[2 * i + 1]}; };
    auto values = [&](std::size_t n, auto&& f) {
      std::vector<double> out(n);
      for (std::size_t i = 0; i < n; ++i) out[i] = f(i);
      return Json::object({{"values", encode(out, 1)}});
    };
    auto directions = [&](std::size_t n, auto&& f) {
      std::vector<double> out(3 * n);
      for (std::size_t i = 0; i < n; ++i) {
        Vec3 m = f(i);
        out[3 * i] = m[0], out[3 * i + 1] = m[1], out[3 * i + 2] = m[2];
      }
      return Json::object({{"m", encode(out, 3)}});
    };

    if (op == "d" || op == "pdf_wm") {
      const auto& f = op == "d" ? model_.d : model_.pdf_wm;
      missing(bool(f));
      const Arrays r = items({{"m", 3}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return values(n, [&](std::size_t i) { return f(vec3(a[0], i)); });
    }
    if (op == "lambda") {
      missing(bool(model_.lambda));
      const Arrays r = items({{"w", 3}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return values(n, [&](std::size_t i) { return model_.lambda(vec3(a[0], i)); });
    }
    if (op == "g1") {
      missing(bool(model_.g1));
      const Arrays r = items({{"w", 3}, {"m", 3}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return values(n, [&](std::size_t i) { return model_.g1(vec3(a[0], i), vec3(a[1], i)); });
    }
    if (op == "g2") {
      missing(bool(model_.g2));
      const Json* masking = request.find("masking");
      Masking form;
      if (masking != nullptr && masking->is_string() && masking->as_string() == "uncorrelated")
        form = Masking::Uncorrelated;
      else if (masking != nullptr && masking->is_string() && masking->as_string() == "height_correlated")
        form = Masking::HeightCorrelated;
      else
        throw ProtocolError("\"masking\" must be \"uncorrelated\" or \"height_correlated\"");
      const Arrays r = items({{"wo", 3}, {"wi", 3}, {"m", 3}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return values(n, [&](std::size_t i) { return model_.g2(vec3(a[0], i), vec3(a[1], i), vec3(a[2], i), form); });
    }
    if (op == "sample_wm") {
      missing(bool(model_.sample_wm));
      const Arrays r = items({{"u", 2}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return directions(n, [&](std::size_t i) { return model_.sample_wm(pair(a[0], i)); });
    }
    if (op == "sample_wm_visible") {
      missing(bool(model_.sample_wm_visible));
      const Arrays r = items({{"wi", 3}, {"u", 2}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return directions(n, [&](std::size_t i) { return model_.sample_wm_visible(vec3(a[0], i), pair(a[1], i)); });
    }
    if (op == "pdf_wm_visible") {
      missing(bool(model_.pdf_wm_visible));
      const Arrays r = items({{"wi", 3}, {"m", 3}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return values(n, [&](std::size_t i) { return model_.pdf_wm_visible(vec3(a[0], i), vec3(a[1], i)); });
    }
    if (op == "bsdf_eval" || op == "bsdf_pdf") {
      const auto& f = op == "bsdf_eval" ? model_.bsdf_eval : model_.bsdf_pdf;
      missing(bool(f));
      const Arrays r = items({{"wi", 3}, {"wo", 3}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      return values(n, [&](std::size_t i) { return f(vec3(a[0], i), vec3(a[1], i)); });
    }
    if (op == "bsdf_sample") {
      missing(bool(model_.bsdf_sample));
      const Arrays r = items({{"wi", 3}, {"u", 3}});
      const auto& a = r.data;
      const std::size_t n = r.n;
      std::vector<double> wo(3 * n), pdf(n), weight(n);
      for (std::size_t i = 0; i < n; ++i) {
        const auto& u = a[1];
        BsdfSample s = model_.bsdf_sample(vec3(a[0], i), Triple{u[3 * i], u[3 * i + 1], u[3 * i + 2]});
        wo[3 * i] = s.wo[0], wo[3 * i + 1] = s.wo[1], wo[3 * i + 2] = s.wo[2];
        pdf[i] = s.pdf;
        weight[i] = s.weight;
      }
      return Json::object({{"wo", encode(wo, 3)}, {"pdf", encode(pdf, 1)}, {"weight", encode(weight, 1)}});
    }
    throw ProtocolError("unknown op \"" + op + "\"");
  }

  Model model_;
  int max_version_;
  int version_ = 1;
};

/// Answers mfh's requests from `in` on `out` until shutdown or the end of `in`; returns the
/// process exit status (0; 2 if a line exceeded kMaxLineBytes, after answering it with an
/// error).
inline int serve(const Model& model, int max_version = 2, std::istream& in = std::cin,
                 std::ostream& out = std::cout) {
  std::ios::sync_with_stdio(false);
  Server server(model, max_version);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line.size() > kMaxLineBytes) {
      out << "{\"id\":null,\"error\":\"a request line of " << line.size() << " bytes (at most "
          << kMaxLineBytes << ")\"}\n"
          << std::flush;
      return 2;
    }
    bool stop = false;
    std::string reply = server.answer(line, stop);
    if (stop) break;
    out << reply << '\n' << std::flush;
  }
  return 0;
}

/// The command line as --name value pairs, with typed getters whose errors name the option.
class Options {
 public:
  Options(int argc, char** argv) {
    for (int i = 1; i < argc; i += 2) {
      std::string name = argv[i];
      if (name.rfind("--", 0) != 0) throw std::invalid_argument("expected an option --name, got \"" + name + "\"");
      if (i + 1 >= argc) throw std::invalid_argument("option " + name + " needs a value");
      pairs_.emplace_back(name, argv[i + 1]);
    }
  }
  /// Whether option `name` was given.
  bool has(const std::string& name) const {
    for (auto& [k, v] : pairs_)
      if (k == name) return true;
    return false;
  }
  /// The text of option `name`, or `fallback`.
  std::string text(const std::string& name, const std::string& fallback) const {
    for (auto& [k, v] : pairs_)
      if (k == name) return v;
    return fallback;
  }
  /// The number of option `name` (finite, within [lo, hi]), or `fallback`.
  double number(const std::string& name, double fallback, double lo, double hi) const {
    if (!has(name)) return fallback;
    std::string t = text(name, "");
    double x = 0.0;
    std::size_t used = 0;
    try {
      x = std::stod(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != t.size() || !std::isfinite(x) || x < lo || x > hi)
      throw std::invalid_argument(name + " is \"" + t + "\"; it must be a number in [" + shortest(lo) +
                                  ", " + shortest(hi) + "]");
    return x;
  }
  static std::string shortest(double x) {
    std::string out;
    detail::write_number(out, x);
    return out;
  }

  /// Fails on an option not in `known`.
  void only(const std::vector<std::string>& known) const {
    for (auto& [k, v] : pairs_) {
      bool ok = false;
      for (auto& n : known) ok = ok || n == k;
      if (!ok) {
        std::string list;
        for (auto& n : known) list += (list.empty() ? "" : ", ") + n;
        throw std::invalid_argument("unknown option " + k + " (known: " + list + ")");
      }
    }
  }

 private:
  std::vector<std::pair<std::string, std::string>> pairs_;
};

}  // namespace mfh

#endif  // MFH_PROTOCOL_HPP
