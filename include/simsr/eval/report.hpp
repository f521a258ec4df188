#pragma once
/// \file
/// Files people open directly: frame-wise errors as CSV (Fig. 5), the statistics table as CSV,
/// and a self-contained SVG line plot of per-frame errors (no plotting library needed).

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../io/atomic_file.hpp"
#include "error_statistics.hpp"

namespace simsr::eval {

/// One method's frame-wise series.
struct Series {
  std::string name;
  std::vector<double> values;
};

namespace detail {
/// Every file of the area is written atomically (io/atomic_file.hpp): WriteError when it cannot be.
inline void write_file(const std::filesystem::path& path, const std::string& text) { io::write_file_atomic(path, text); }
inline std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}
inline std::string xml_text(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return o;
}
/// The opening of a plot's SVG: a white page, the title and the two axes (every plot's).
inline void svg_frame(std::ostringstream& o, double W, double H, double left, double right, double top, double bottom, const std::string& title) {
  o.imbue(std::locale::classic());
  o << std::setprecision(6);
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << W / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << xml_text(title) << "</text>\n"
    << "<line x1=\"" << left << "\" y1=\"" << H - bottom << "\" x2=\"" << W - right << "\" y2=\"" << H - bottom << "\" stroke=\"black\"/>\n"
    << "<line x1=\"" << left << "\" y1=\"" << top << "\" x2=\"" << left << "\" y2=\"" << H - bottom << "\" stroke=\"black\"/>\n";
}
inline constexpr const char* plot_colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"};
}  // namespace detail

/// CSV with a `frame` column and one column per series (all series the same length).
inline void write_frame_csv(const std::filesystem::path& path, const std::vector<Series>& series,
                            const std::vector<long long>& frame_ids = {}) {
  if (series.empty()) throw ArgumentError("write_frame_csv: no series");
  const std::size_t n = series.front().values.size();
  for (const auto& s : series)
    if (s.values.size() != n) throw ShapeError("write_frame_csv: series " + s.name, {Index(n)}, {Index(s.values.size())});
  if (!frame_ids.empty() && frame_ids.size() != n) throw ShapeError("write_frame_csv: frame ids", {Index(n)}, {Index(frame_ids.size())});
  std::ostringstream o;
  o.imbue(std::locale::classic());
  o << std::setprecision(10) << "frame";
  for (const auto& s : series) o << ',' << detail::csv_field(s.name);
  o << '\n';
  for (std::size_t f = 0; f < n; ++f) {
    o << (frame_ids.empty() ? static_cast<long long>(f) : frame_ids[f]);
    for (const auto& s : series) o << ',' << s.values[f];
    o << '\n';
  }
  detail::write_file(path, o.str());
}

/// CSV of Table-1 statistics, one row per method: raw, relative to the diagonal, and normalized to
/// the largest value across methods.
inline void write_statistics_csv(const std::filesystem::path& path, const std::vector<std::string>& methods,
                                 const std::vector<ErrorStatistics>& raw, double diagonal) {
  if (methods.size() != raw.size()) throw ShapeError("write_statistics_csv: methods vs statistics", {Index(methods.size())}, {Index(raw.size())});
  const auto norm = normalized_to_largest(raw);
  std::ostringstream o;
  o.imbue(std::locale::classic());
  o << std::setprecision(10);
  o << "method,count,mean,median,std,max,min,rel_mean,rel_median,rel_std,rel_max,rel_min,"
       "norm_mean,norm_median,norm_std,norm_max,norm_min\n";
  for (std::size_t i = 0; i < methods.size(); ++i) {
    const auto& r = raw[i];
    const auto rel = r.scaled(diagonal);
    const auto& n = norm[i];
    o << detail::csv_field(methods[i]) << ',' << r.count;
    for (const auto* s : {&r, &rel, &n}) o << ',' << s->mean << ',' << s->median << ',' << s->std << ',' << s->max << ',' << s->min;
    o << '\n';
  }
  detail::write_file(path, o.str());
}

/// A line plot of the series against their index as a standalone SVG (opens in any browser).
/// `log_y` plots log10 of the values (non-positive values are drawn at the bottom), for methods
/// whose errors differ by orders of magnitude.
inline void write_svg_plot(const std::filesystem::path& path, const std::vector<Series>& series, const std::string& title,
                           const std::string& y_label, bool log_y = false, const std::string& x_label = "frame") {
  if (series.empty()) throw ArgumentError("write_svg_plot: no series");
  const double W = 900, H = 480, left = 90, right = 200, top = 40, bottom = 50;
  std::size_t n = 0;
  double ymax = 0, ymin_pos = std::numeric_limits<double>::infinity();
  for (const auto& s : series) {
    n = std::max(n, s.values.size());
    for (double v : s.values)
      if (std::isfinite(v)) ymax = std::max(ymax, v), ymin_pos = v > 0 ? std::min(ymin_pos, v) : ymin_pos;
  }
  if (ymax <= 0) ymax = 1;
  // Vertical axis: [0, ymax] linear, or whole decades [10^lo, 10^hi] on a log scale.
  const double lo = log_y ? std::floor(std::log10(std::isfinite(ymin_pos) ? ymin_pos : ymax)) : 0.0;
  const double hi = log_y ? std::max(lo + 1, std::ceil(std::log10(ymax))) : ymax;
  auto ypos = [&](double v) {
    const double t = log_y ? (v > 0 ? (std::log10(v) - lo) / (hi - lo) : 0.0) : v / hi;
    return H - bottom - std::clamp(t, 0.0, 1.0) * (H - top - bottom);
  };
  const double xs = (W - left - right) / double(std::max<std::size_t>(n - (n > 0), 1));
  std::ostringstream o;
  detail::svg_frame(o, W, H, left, right, top, bottom, title);
  const int yticks = log_y ? int(hi - lo) : 4;
  for (int t = 0; t <= yticks; ++t) {  // y ticks
    const double v = log_y ? std::pow(10.0, lo + t) : hi * t / 4, y = ypos(v);
    o << std::setprecision(3) << "<line x1=\"" << left - 4 << "\" y1=\"" << y << "\" x2=\"" << W - right << "\" y2=\"" << y << "\" stroke=\"#ddd\"/>"
      << "<text x=\"" << left - 6 << "\" y=\"" << y + 4 << "\" text-anchor=\"end\">" << v << "</text>\n";
  }
  for (int t = 0; t <= 4 && n > 1; ++t) {  // x ticks
    const double f = std::round(double(n - 1) * t / 4), x = left + f * xs;
    o << "<text x=\"" << x << "\" y=\"" << H - bottom + 18 << "\" text-anchor=\"middle\">" << f << "</text>\n";
  }
  o << std::setprecision(6) << "<text x=\"" << (left + W - right) / 2 << "\" y=\"" << H - 10 << "\" text-anchor=\"middle\">"
    << detail::xml_text(x_label) << "</text>\n"
    << "<text x=\"16\" y=\"" << (top + H - bottom) / 2 << "\" transform=\"rotate(-90 16 " << (top + H - bottom) / 2
    << ")\" text-anchor=\"middle\">" << detail::xml_text(y_label) << "</text>\n";
  for (std::size_t i = 0; i < series.size(); ++i) {
    const char* c = detail::plot_colors[i % 8];
    o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.5\" points=\"";
    for (std::size_t f = 0; f < series[i].values.size(); ++f)
      o << left + double(f) * xs << ',' << ypos(series[i].values[f]) << ' ';
    o << "\"/>\n<rect x=\"" << W - right + 15 << "\" y=\"" << top + 20.0 * double(i) << "\" width=\"12\" height=\"12\" fill=\"" << c
      << "\"/><text x=\"" << W - right + 32 << "\" y=\"" << top + 20.0 * double(i) + 11 << "\">" << detail::xml_text(series[i].name) << "</text>\n";
  }
  o << "</svg>\n";
  detail::write_file(path, o.str());
}

/// A plot of the series against the values `x` (every series as long as x; ascending x), lines
/// with a marker at each point, as a standalone SVG: a sweep of one parameter (Fig. 9).
inline void write_svg_xy_plot(const std::filesystem::path& path, const std::vector<double>& x, const std::vector<Series>& series,
                              const std::string& title, const std::string& y_label, const std::string& x_label) {
  if (series.empty() || x.empty()) throw ArgumentError("write_svg_xy_plot: no series or no x values");
  for (const auto& s : series)
    if (s.values.size() != x.size())
      throw ArgumentError("write_svg_xy_plot: series '" + s.name + "' has " + std::to_string(s.values.size()) + " values for " + std::to_string(x.size()) + " x values");
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]) || (i > 0 && !(x[i] > x[i - 1]))) throw ArgumentError("write_svg_xy_plot: x values must be finite and ascending");
  const double W = 900, H = 480, left = 90, right = 220, top = 40, bottom = 50;
  double ymax = 0;
  for (const auto& s : series)
    for (double v : s.values)
      if (std::isfinite(v)) ymax = std::max(ymax, v);
  if (ymax <= 0) ymax = 1;
  const double x0 = x.front(), x1 = x.size() > 1 ? x.back() : x.front() + 1;
  auto xpos = [&](double v) { return left + (v - x0) / (x1 - x0) * (W - left - right); };
  auto ypos = [&](double v) { return H - bottom - std::clamp(v / ymax, 0.0, 1.0) * (H - top - bottom); };
  std::ostringstream o;
  detail::svg_frame(o, W, H, left, right, top, bottom, title);
  for (int t = 0; t <= 4; ++t) {
    const double v = ymax * t / 4, y = ypos(v);
    o << std::setprecision(3) << "<line x1=\"" << left - 4 << "\" y1=\"" << y << "\" x2=\"" << W - right << "\" y2=\"" << y << "\" stroke=\"#ddd\"/>"
      << "<text x=\"" << left - 6 << "\" y=\"" << y + 4 << "\" text-anchor=\"end\">" << v << "</text>\n";
  }
  for (double v : x)
    o << std::setprecision(6) << "<text x=\"" << xpos(v) << "\" y=\"" << H - bottom + 18 << "\" text-anchor=\"middle\">" << v << "</text>\n";
  o << "<text x=\"" << (left + W - right) / 2 << "\" y=\"" << H - 10 << "\" text-anchor=\"middle\">" << detail::xml_text(x_label) << "</text>\n"
    << "<text x=\"16\" y=\"" << (top + H - bottom) / 2 << "\" transform=\"rotate(-90 16 " << (top + H - bottom) / 2 << ")\" text-anchor=\"middle\">"
    << detail::xml_text(y_label) << "</text>\n";
  for (std::size_t i = 0; i < series.size(); ++i) {
    const char* c = detail::plot_colors[i % 8];
    o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.5\" points=\"";
    for (std::size_t k = 0; k < x.size(); ++k) o << xpos(x[k]) << ',' << ypos(series[i].values[k]) << ' ';
    o << "\"/>\n";
    for (std::size_t k = 0; k < x.size(); ++k)
      o << "<circle cx=\"" << xpos(x[k]) << "\" cy=\"" << ypos(series[i].values[k]) << "\" r=\"3\" fill=\"" << c << "\"/>";
    o << "\n<rect x=\"" << W - right + 15 << "\" y=\"" << top + 20.0 * double(i) << "\" width=\"12\" height=\"12\" fill=\"" << c
      << "\"/><text x=\"" << W - right + 32 << "\" y=\"" << top + 20.0 * double(i) + 11 << "\">" << detail::xml_text(series[i].name) << "</text>\n";
  }
  o << "</svg>\n";
  detail::write_file(path, o.str());
}

}  // namespace simsr::eval
