// Text formatting shared by the studies' reports (CSV and Markdown tables): numbers that read back
// exactly, fixed and significant-digit forms, and quoting of CSV fields (RFC 4180) and Markdown
// table cells.
#pragma once

#include <string>

namespace clothsim {

// Shortest decimal form that reads back to the identical double ("0.001", "1e-05"); "nan", "inf",
// "-inf" for those.
std::string format_shortest(double v);

// `digits` decimals ("12.345600" for 6); non-finite values as format_shortest.
std::string format_fixed(double v, int digits);

// `digits` significant digits in %g style ("0.0123", "1.23e-05"); non-finite as format_shortest.
std::string format_significant(double v, int digits);

// `s` as one CSV field: unchanged unless it holds a comma, quote, CR or LF; then quoted, with
// quotes doubled (RFC 4180).
std::string csv_field(const std::string& s);

// `s` with '|' escaped so that it stays inside one Markdown table cell.
std::string markdown_cell(const std::string& s);

}  // namespace clothsim
