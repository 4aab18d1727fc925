#pragma once
// Text helpers shared by the core, the CLI and the ROS layer: the one number formatter and the
// one hash of the package.
#include <cstdint>
#include <string>

namespace amytiss {

/// Shortest decimal text of 15 to 17 significant digits that reads back to the same double
/// ("0.1", "1e-12", "-2.5"); "nan", "inf", "-inf" for non-finite values.
std::string format_number(double value);
/// format_number() as a C / OpenCL C double literal: ".0" appended when the text has neither a
/// point nor an exponent ("10" -> "10.0"). Reads back to the same double.
std::string c_double_literal(double value);

/// A figure for people with `digits` significant digits, as printf's %g ("0.00032", "1.5e+07").
std::string format_significant(double value, int digits = 3);

/// Bytes for people: "512 B", "3.2 KiB", "1.5 MiB", "2.0 GiB" (binary units, one decimal).
std::string format_bytes(double bytes);

/// FNV-1a 64-bit offset basis (the standard start of the hash).
constexpr std::uint64_t kFnvOffsetBasis = 14695981039346656037ull;
/// FNV-1a 64-bit hash of the bytes of `text`, started from `basis`.
std::uint64_t fnv1a64(const std::string& text, std::uint64_t basis = kFnvOffsetBasis);
/// The value as 16 lowercase hexadecimal digits.
std::string hex16(std::uint64_t value);

}  // namespace amytiss
