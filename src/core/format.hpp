// occull — the culling core's messages, formatted without a formatting library.
//
// occull::core depends on the standard library, glm and Highway only (an
// engine takes it as it takes meshoptimizer), and GCC 12 has no <format>.
// Its error messages need little: "{}" for a value and "{:.Nf}" for a fixed
// number of decimals, which this writes as fmt would.
#pragma once

#include <charconv>
#include <concepts>
#include <string>
#include <string_view>
#include <type_traits>

namespace occull::detail {

/// Appends `value` to `out` as fmt's "{}" would: integers in decimal,
/// floating-point numbers in their shortest form that reads back exactly
/// (fixed notation for exponents in [-4, 16)), bools as true/false, text as
/// it is. `decimals` >= 0 (a "{:.Nf}" field)
/// writes a floating-point number in fixed notation with that many digits.
template <typename T>
void append_formatted(std::string& out, const T& value, int decimals) {
  using V = std::remove_cvref_t<T>;
  if constexpr (std::is_same_v<V, bool>) {
    out += value ? "true" : "false";
  } else if constexpr (std::is_same_v<V, char>) {
    out += value;
  } else if constexpr (std::is_arithmetic_v<V>) {
    char buffer[64];
    std::to_chars_result r{};
    if constexpr (std::floating_point<V>) {
      if (decimals >= 0) {
        r = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, decimals);
      } else {
        // fmt's "{}": the shortest digits that read back exactly, in fixed
        // notation for decimal exponents in [-4, 16) (the digits padded with
        // zeros), else in scientific ("1e-05", "1.5e+16").
        r = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::scientific);
        const std::string_view sci(buffer, std::size_t(r.ptr - buffer));
        const std::size_t e = sci.find('e');
        int exponent = 0;
        if (e != std::string_view::npos)
          std::from_chars(sci.data() + e + (sci[e + 1] == '+' ? 2 : 1), sci.data() + sci.size(), exponent);
        if (e != std::string_view::npos && exponent >= -4 && exponent < 16) {
          const bool negative = sci.front() == '-';
          std::string digits;
          for (char c : sci.substr(negative ? 1 : 0, e - (negative ? 1 : 0)))
            if (c != '.') digits += c;
          std::string fixed = negative ? "-" : "";
          if (exponent < 0) {
            fixed += "0." + std::string(std::size_t(-exponent - 1), '0') + digits;
          } else if (std::size_t(exponent) + 1 >= digits.size()) {
            fixed += digits + std::string(std::size_t(exponent) + 1 - digits.size(), '0');
          } else {
            fixed += digits.substr(0, std::size_t(exponent) + 1) + "." + digits.substr(std::size_t(exponent) + 1);
          }
          out += fixed;
          return;
        }
      }
    } else {
      r = std::to_chars(buffer, buffer + sizeof buffer, value);
    }
    // Only a fixed-notation number too long for the buffer (above 1e40) fails: write it in full.
    if (r.ec != std::errc{}) out += std::to_string(value);
    else out.append(buffer, r.ptr);
  } else {
    out += std::string_view(value);
  }
}

/// `pattern` with each "{}" (or "{:.Nf}") replaced by the next argument;
/// "{{" and "}}" write a brace. Preconditions: as many fields as arguments,
/// each field "{}" or "{:.Nf}" with N in 0..9 (a pattern is a literal in the
/// source, so a mistake shows in the first test that throws the message).
template <typename... Args>
[[nodiscard]] std::string format(std::string_view pattern, const Args&... args) {
  std::string out;
  out.reserve(pattern.size() + 16 * sizeof...(Args));
  std::size_t at = 0;
  // Writes the pattern up to its next field, then returns that field's decimals (-1: none given).
  const auto next_field = [&]() -> int {
    while (at < pattern.size()) {
      const char c = pattern[at];
      if ((c == '{' || c == '}') && at + 1 < pattern.size() && pattern[at + 1] == c) {
        out += c;
        at += 2;
      } else if (c == '{') {
        const std::size_t end = pattern.find('}', at);
        const std::string_view spec = pattern.substr(at + 1, end - at - 1);
        at = end + 1;
        int decimals = -1;
        if (spec.size() == 4 && spec.starts_with(":.") && spec.ends_with('f')) decimals = spec.at(2) - '0';
        return decimals;
      } else {
        out += c;
        ++at;
      }
    }
    return -1;
  };
  (append_formatted(out, args, next_field()), ...);
  next_field();  // the text after the last field
  return out;
}

}  // namespace occull::detail
