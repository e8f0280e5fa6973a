#include "reports/history.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <optional>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/nan.h"
#include "core/statistics.h"
#include "core/text_pattern.h"
#include "reports/html_page.h"
#include "reports/pdf_flow.h"
#include "schema/summary.h"

namespace arcwheel::reports {
namespace {

namespace key = schema::summary;
constexpr const char* kHistoryStage = "reports.history";
constexpr double kSecondsPerHour = 3600.0;

std::string ScanString(const Summary& s, std::string_view name) {
  const auto it = s.scan.find(name);
  return it != s.scan.end() && it->is_string() ? it->get<std::string>() : "";
}

std::string Trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

// ---- Figures ----

double HoursSince(const History& h, double time_s) {
  return (time_s - h.scans.front().time_s) / kSecondsPerHour;
}

std::vector<double> ScanHours(const History& h) {
  std::vector<double> hours;
  for (const HistoryScan& scan : h.scans) hours.push_back(HoursSince(h, scan.time_s));
  return hours;
}

std::vector<double> DressingHours(const History& h) {
  std::vector<double> hours;
  for (double t : h.dressing_times_s) hours.push_back(HoursSince(h, t));
  return hours;
}

template <typename Get>
std::vector<double> Values(const History& h, const Get& get) {
  std::vector<double> values;
  for (const HistoryScan& scan : h.scans) values.push_back(get(scan.summary));
  return values;
}

ReportFigure RadiusFigure(const History& h) {
  const double reference_mm = h.scans.front().summary.mean_arc_radius_mm;
  plot::Series radius{
      "mean arc radius ± 1σ",
      ScanHours(h),
      Values(h, [&](const Summary& s) { return (s.mean_arc_radius_mm - reference_mm) * 1000.0; }),
      {},
      {},
      plot::SeriesColour(0),
      true};
  radius.y_error = Values(h, [](const Summary& s) { return s.mean_arc_radius_sigma_mm * 1000.0; });
  radius.marker_size_pt = 2.2;
  plot::LinePlot plot{"Mean arc radius against scan time",
                      {"time since the first scan (h)"},
                      {"mean arc radius − " + FormatValue(reference_mm, units::kRadius_mm) + " (µm)"},
                      {radius},
                      {}};
  for (const WearRate& w : h.wear) {
    plot::Series line{
        fmt::format("wear fit, segment {}", w.segment), {}, {}, {}, {}, plot::SeriesColour(1), false, true};
    for (const double t : {w.first_time_s, w.last_time_s}) {
      line.x.push_back(HoursSince(h, t));
      line.y.push_back((w.intercept_mm - reference_mm) * 1000.0 +
                       w.rate_um_per_h * (t - w.first_time_s) / kSecondsPerHour);
    }
    plot.series.push_back(line);
  }
  plot.x_marks = DressingHours(h);
  plot.x_marks_label = "dressing";
  return {
      "Mean arc radius of each scan with its 1-sigma (σ of the mean), relative to the first scan; dashed: "
      "the weighted least-squares wear line of each segment between dressings.",
      plot, 0.5};
}

ReportFigure PeakToValleyFigure(const History& h) {
  const std::vector<double> hours = ScanHours(h);
  plot::LinePlot plot{"Peak-to-valley figures against scan time",
                      {"time since the first scan (h)"},
                      {"peak-to-valley (µm)"},
                      {{"max arc error",
                        hours,
                        Values(h, [](const Summary& s) { return s.max_arc_error_um; }),
                        {},
                        {},
                        plot::SeriesColour(2),
                        true},
                       {"max runout",
                        hours,
                        Values(h, [](const Summary& s) { return s.max_runout_um; }),
                        {},
                        {},
                        plot::SeriesColour(0),
                        true},
                       {"max roundness",
                        hours,
                        Values(h, [](const Summary& s) { return s.max_roundness_um; }),
                        {},
                        {},
                        plot::SeriesColour(4),
                        true},
                       {"arc radius range",
                        hours,
                        Values(h, [](const Summary& s) { return s.arc_radius_range_mm * 1000.0; }),
                        {},
                        {},
                        plot::SeriesColour(3),
                        true}},
                      {}};
  for (plot::Series& series : plot.series) series.marker_size_pt = 2.2;
  plot.x_marks = DressingHours(h);
  plot.x_marks_label = "dressing";
  return {
      "Peak-to-valley figures of each scan (no sigma is recorded for them; the inspection report of each "
      "scan gives the part that noise explains).",
      plot, 0.5};
}

std::string WearText(const WearRate& w) {
  std::string text = FormatWithSigma(w.rate_um_per_h, w.sigma_um_per_h, units::kWear_um_per_h);
  if (w.repeatability_um > 0.0) {
    text += " (χ²/dof " + FormatFixed(w.chi2_per_dof_scans_alone, 2) +
            " with the scans' σ alone; repeatability s_R " + FormatFixed(w.repeatability_um, 3) +
            " µm added: χ²/dof " + FormatFixed(w.chi2_per_dof, 2) + ")";
  } else if (std::isfinite(w.chi2_per_dof)) {
    text += " (χ²/dof " + FormatFixed(w.chi2_per_dof, 2) + ")";
  }
  return text;
}

std::vector<std::vector<std::string>> WearRows(const History& h) {
  std::vector<std::vector<std::string>> rows;
  for (const WearRate& w : h.wear) {
    rows.push_back({std::to_string(w.segment), std::to_string(w.scans),
                    FormatFixed((w.last_time_s - w.first_time_s) / kSecondsPerHour, 2) + " h", WearText(w)});
  }
  return rows;
}

std::vector<std::vector<std::string>> ScanRows(const History& h) {
  std::vector<std::vector<std::string>> rows;
  for (const HistoryScan& scan : h.scans) {
    const Summary& s = scan.summary;
    rows.push_back({scan.timestamp, std::to_string(scan.segment),
                    FormatWithSigma(s.mean_arc_radius_mm, s.mean_arc_radius_sigma_mm, units::kRadius_mm),
                    FormatValue(s.max_arc_error_um, units::kLength_um),
                    FormatValue(s.max_runout_um, units::kLength_um), scan.folder.string()});
  }
  return rows;
}

const std::vector<std::string> kWearHeader = {"Segment", "Scans", "Span",
                                              "Wear rate (radius change per hour) ± 1σ"};
const std::vector<std::string> kScanHeader = {
    "Scan time", "Segment", "Mean arc radius ± σ of the mean", "Max arc error", "Max runout", "Folder"};

std::string Title(const History& h) {
  return "Wheel history: " + (h.wheel_id.empty() ? "wheel id not recorded" : h.wheel_id);
}

std::string RuleText() {
  return "Dressings split the scans into segments (0 before the first). Wear rate: weighted least-squares "
         "slope "
         "of the mean arc radius against scan time (weights 1/σ², σ the σ of the mean), per hour of elapsed "
         "time; its σ from the scans' σ, scaled by √(χ²/dof) when the scatter exceeds them. Negative: the "
         "radius shrinks.";
}

std::string DressingText(const History& h) {
  if (h.dressing_timestamps.empty()) return "No dressings given (--dressings FILE.csv).";
  std::string text = "Dressings: ";
  for (std::size_t i = 0; i < h.dressing_timestamps.size(); ++i)
    text += (i ? ", " : "") + h.dressing_timestamps[i];
  return text + ".";
}

std::string RenderHistoryHtml(const History& h) {
  using namespace internal;
  std::string html = HtmlPageStart(Title(h));
  html += "<h2>Wear between dressings</h2>\n";
  html +=
      h.wear.empty() ? "<p>No segment holds two scans: no wear rate.</p>\n" : Table(kWearHeader, WearRows(h));
  html += "<p>" + Escape(RuleText()) + "</p>\n<p>" + Escape(DressingText(h)) + "</p>\n";
  html += "<h2>Plots</h2>\n" + FigureHtml(RadiusFigure(h), kFigureWidth_pt, "h0-") +
          FigureHtml(PeakToValleyFigure(h), kFigureWidth_pt, "h1-");
  html += "<h2>Scans</h2>\n" + Table(kScanHeader, ScanRows(h));
  return html + HtmlPageEnd();
}

void TableRows(internal::PdfFlow& pdf, const std::vector<std::string>& header,
               const std::vector<std::vector<std::string>>& rows, const std::vector<double>& fractions) {
  std::vector<double> widths;
  for (double f : fractions) widths.push_back(f * internal::kContentWidth_pt);
  auto cells = [](const std::vector<std::string>& texts) {
    std::vector<internal::Cell> out;
    for (const std::string& text : texts) out.push_back({text, {}});
    return out;
  };
  pdf.TableHeader(cells(header), widths);
  for (const std::vector<std::string>& row : rows) pdf.Row(cells(row), widths, false);
  pdf.EndTable();
}

void LayoutHistoryPdf(internal::PdfFlow& pdf, const History& h) {
  using internal::kLine_pt;
  pdf.SetMetadata(Title(h));
  pdf.Title(Title(h));
  pdf.Heading("Wear between dressings", 3 * kLine_pt);
  if (h.wear.empty())
    pdf.Paragraph("No segment holds two scans: no wear rate.");
  else
    TableRows(pdf, kWearHeader, WearRows(h), {0.12, 0.10, 0.18, 0.60});
  pdf.Paragraph(RuleText());
  pdf.Paragraph(DressingText(h));
  pdf.Heading("Plots", 20 * kLine_pt);
  pdf.Figure(RadiusFigure(h));
  pdf.Figure(PeakToValleyFigure(h));
  pdf.Heading("Scans", 3 * kLine_pt);
  TableRows(pdf, kScanHeader, ScanRows(h), {0.20, 0.09, 0.22, 0.12, 0.12, 0.25});
  pdf.Finish();
}

}  // namespace

double ParseTimestamp_s(const std::string& text, const std::string& where) {
  static const TextPattern kIso(
      R"(^(\d{4})-(\d{2})-(\d{2})[T ](\d{2}):(\d{2})(?::(\d{2})(\.\d+)?)?(Z|[+-]\d{2}:?\d{2})?$)");
  const auto m = kIso.MatchWhole(Trim(text));
  if (!m) {
    throw Error(ErrorCode::kBadInput, kHistoryStage,
                where + " '" + text + "' is not an ISO 8601 date and time (e.g. 2026-03-01T08:30:00Z)");
  }
  const std::vector<std::optional<std::string>>& g = *m;
  std::tm t{};
  t.tm_year = std::stoi(*g[1]) - 1900;
  t.tm_mon = std::stoi(*g[2]) - 1;
  t.tm_mday = std::stoi(*g[3]);
  t.tm_hour = std::stoi(*g[4]);
  t.tm_min = std::stoi(*g[5]);
  t.tm_sec = g[6] ? std::stoi(*g[6]) : 0;
  if (t.tm_mon > 11 || t.tm_mday < 1 || t.tm_mday > 31 || t.tm_hour > 23 || t.tm_min > 59 || t.tm_sec > 60)
    throw Error(ErrorCode::kBadInput, kHistoryStage, where + " '" + text + "' is not a valid date and time");
  double seconds = static_cast<double>(timegm(&t));
  if (g[7]) seconds += std::stod(*g[7]);
  if (g[8] && *g[8] != "Z") {
    const std::string& zone = *g[8];
    const int hours = std::stoi(zone.substr(1, 2));
    const int minutes = std::stoi(zone.substr(zone.size() - 2));
    seconds -= (zone[0] == '-' ? -1.0 : 1.0) * (hours * 3600.0 + minutes * 60.0);
  }
  return seconds;
}

std::vector<double> ParseDressingsCsv(const std::string& text, const std::string& name,
                                      std::vector<std::string>* timestamps) {
  std::vector<double> times;
  std::istringstream lines(text);
  int number = 0;
  bool first_content = true;
  for (std::string line; std::getline(lines, line);) {
    ++number;
    const std::string cell = Trim(line.substr(0, line.find(',')));
    if (cell.empty() || cell[0] == '#') continue;
    const bool header = first_content && !std::isdigit(static_cast<unsigned char>(cell[0]));
    first_content = false;
    if (header) continue;
    times.push_back(ParseTimestamp_s(cell, fmt::format("'{}' line {}:", name, number)));
    if (timestamps != nullptr) timestamps->push_back(cell);
  }
  if (times.empty())
    throw Error(ErrorCode::kBadInput, kHistoryStage, "'" + name + "' holds no dressing date");
  return times;
}

namespace {

// The weighted least-squares line of radius against time (hours from the first scan) with each
// scan's sigma widened by `extra_mm` in quadrature; its chi-square.
struct Line {
  double slope_mm_per_h = 0.0, sigma_mm_per_h = 0.0, intercept_mm = 0.0, chi2 = 0.0;
};

Line FitLine(const std::vector<double>& time_s, const std::vector<double>& radius_mm,
             const std::vector<double>& sigma_mm, double extra_mm) {
  const double t0 = time_s.front();
  double sw = 0.0, swt = 0.0, swr = 0.0;
  for (std::size_t i = 0; i < time_s.size(); ++i) {
    const double weight = 1.0 / (sigma_mm[i] * sigma_mm[i] + extra_mm * extra_mm);
    const double t = (time_s[i] - t0) / kSecondsPerHour;
    sw += weight, swt += weight * t, swr += weight * radius_mm[i];
  }
  const double t_mean = swt / sw, r_mean = swr / sw;
  double stt = 0.0, str = 0.0;
  for (std::size_t i = 0; i < time_s.size(); ++i) {
    const double weight = 1.0 / (sigma_mm[i] * sigma_mm[i] + extra_mm * extra_mm);
    const double t = (time_s[i] - t0) / kSecondsPerHour - t_mean;
    stt += weight * t * t, str += weight * t * (radius_mm[i] - r_mean);
  }
  Line line;
  line.slope_mm_per_h = str / stt;
  line.sigma_mm_per_h = std::sqrt(1.0 / stt);
  line.intercept_mm = r_mean - line.slope_mm_per_h * t_mean;
  for (std::size_t i = 0; i < time_s.size(); ++i) {
    const double t = (time_s[i] - t0) / kSecondsPerHour;
    const double residual = (radius_mm[i] - line.intercept_mm - line.slope_mm_per_h * t);
    line.chi2 += residual * residual / (sigma_mm[i] * sigma_mm[i] + extra_mm * extra_mm);
  }
  return line;
}

}  // namespace

WearRate FitWearRate(const std::vector<double>& time_s, const std::vector<double>& radius_mm,
                     const std::vector<double>& sigma_mm) {
  WearRate w;
  w.scans = time_s.size();
  w.first_time_s = time_s.front();
  w.last_time_s = time_s.back();
  Line line = FitLine(time_s, radius_mm, sigma_mm, 0.0);
  w.chi2_per_dof = kNaN;
  w.chi2_per_dof_scans_alone = kNaN;
  if (time_s.size() > 2) {
    const double dof = static_cast<double>(time_s.size() - 2);
    w.chi2_per_dof_scans_alone = line.chi2 / dof;
    w.chi2_per_dof = w.chi2_per_dof_scans_alone;
    // Chi-square test of the scans' sigmas alone; rejected at 5 %: a repeatability term s_R found
    // by bisection so that chi-square / dof = 1 (chi-square falls as s_R grows).
    const double p_value = ChiSquaredUpperTail(line.chi2, dof);
    if (p_value < 0.05) {
      double low = 0.0, high = 0.0;
      for (std::size_t i = 0; i < radius_mm.size(); ++i)
        high = std::max(high, std::abs(radius_mm[i] - radius_mm[0]));
      high = std::max(high, 1e-9) * 10.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        const double middle = 0.5 * (low + high);
        (FitLine(time_s, radius_mm, sigma_mm, middle).chi2 > dof ? low : high) = middle;
      }
      w.repeatability_um = 0.5 * (low + high) * 1000.0;
      line = FitLine(time_s, radius_mm, sigma_mm, w.repeatability_um / 1000.0);
      w.chi2_per_dof = line.chi2 / dof;
    } else {
      // Not significant: the rate's sigma still takes the scatter the chi-square shows, if larger.
      line.sigma_mm_per_h *= std::sqrt(std::max(1.0, w.chi2_per_dof));
    }
  }
  w.intercept_mm = line.intercept_mm;
  w.rate_um_per_h = line.slope_mm_per_h * 1000.0;
  w.sigma_um_per_h = line.sigma_mm_per_h * 1000.0;
  return w;
}

History BuildHistory(const std::vector<std::filesystem::path>& folders,
                     const std::vector<double>& dressing_times_s,
                     const std::vector<std::string>& dressing_timestamps) {
  std::string wheel_id;
  std::vector<HistoryScan> scans;
  for (const std::filesystem::path& folder : folders) {
    HistoryScan scan;
    scan.folder = folder;
    const std::filesystem::path path = folder / key::kFileName;
    scan.summary = ReadSummary(path);
    scan.timestamp = ScanString(scan.summary, key::scan::kTimestamp);
    if (scan.timestamp.empty())
      throw Error(ErrorCode::kBadInput, kHistoryStage,
                  "'" + path.string() + "' key 'scan.timestamp' is missing or empty");
    scan.time_s = ParseTimestamp_s(scan.timestamp, "'" + path.string() + "' key 'scan.timestamp'");
    const std::string id = ScanString(scan.summary, key::scan::kWheelId);
    if (!scans.empty() && id != wheel_id) {
      throw Error(ErrorCode::kBadInput, kHistoryStage,
                  fmt::format("'{}' is of wheel '{}' but '{}' of wheel '{}': a history holds one wheel",
                              (scans.front().folder / key::kFileName).string(), wheel_id, path.string(), id));
    }
    wheel_id = id;
    scans.push_back(std::move(scan));
  }
  return AssembleHistory(wheel_id, std::move(scans), dressing_times_s, dressing_timestamps);
}

History AssembleHistory(const std::string& wheel_id, std::vector<HistoryScan> scans,
                        const std::vector<double>& dressing_times_s,
                        const std::vector<std::string>& dressing_timestamps) {
  History h;
  h.wheel_id = wheel_id;
  h.scans = std::move(scans);
  std::stable_sort(h.scans.begin(), h.scans.end(),
                   [](const HistoryScan& a, const HistoryScan& b) { return a.time_s < b.time_s; });
  for (std::size_t i = 1; i < h.scans.size(); ++i) {
    if (h.scans[i].time_s == h.scans[i - 1].time_s) {
      throw Error(
          ErrorCode::kBadInput, kHistoryStage,
          fmt::format("'{}' and '{}' have the same scan timestamp '{}'", h.scans[i - 1].folder.string(),
                      h.scans[i].folder.string(), h.scans[i].timestamp));
    }
  }
  std::vector<std::size_t> order(dressing_times_s.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return dressing_times_s[a] < dressing_times_s[b]; });
  for (std::size_t i : order) {
    h.dressing_times_s.push_back(dressing_times_s[i]);
    h.dressing_timestamps.push_back(i < dressing_timestamps.size() ? dressing_timestamps[i] : "");
  }
  for (HistoryScan& scan : h.scans) {
    scan.segment =
        static_cast<int>(std::upper_bound(h.dressing_times_s.begin(), h.dressing_times_s.end(), scan.time_s) -
                         h.dressing_times_s.begin());
  }
  for (int segment = 0; segment <= static_cast<int>(h.dressing_times_s.size()); ++segment) {
    std::vector<double> t, r, s;
    for (const HistoryScan& scan : h.scans) {
      if (scan.segment != segment || !std::isfinite(scan.summary.mean_arc_radius_mm) ||
          !(scan.summary.mean_arc_radius_sigma_mm > 0.0))
        continue;
      t.push_back(scan.time_s);
      r.push_back(scan.summary.mean_arc_radius_mm);
      s.push_back(scan.summary.mean_arc_radius_sigma_mm);
    }
    if (t.size() < 2) continue;
    WearRate w = FitWearRate(t, r, s);
    w.segment = segment;
    h.wear.push_back(w);
  }
  return h;
}

std::string HistoryCsv(const History& h) {
  std::string csv = "# wheel_id: " + h.wheel_id + "\n";
  for (const WearRate& w : h.wear) {
    csv += fmt::format("# wear segment {}: {} um/h, 1-sigma {} um/h, {} scans, repeatability {} um\n",
                       w.segment, w.rate_um_per_h, w.sigma_um_per_h, w.scans, w.repeatability_um);
  }
  csv +=
      "timestamp,time_h,segment,mean_arc_radius_mm,mean_arc_radius_sigma_mm,arc_radius_range_mm,"
      "center_axial_deviation_mm,max_arc_error_um,max_runout_um,max_roundness_um,folder\n";
  auto number = [](double v) { return std::isfinite(v) ? fmt::format("{}", v) : std::string(); };
  for (const HistoryScan& scan : h.scans) {
    const Summary& s = scan.summary;
    csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", scan.timestamp,
                       number((scan.time_s - h.scans.front().time_s) / kSecondsPerHour), scan.segment,
                       number(s.mean_arc_radius_mm), number(s.mean_arc_radius_sigma_mm),
                       number(s.arc_radius_range_mm), number(s.center_axial_deviation_mm),
                       number(s.max_arc_error_um), number(s.max_runout_um), number(s.max_roundness_um),
                       scan.folder.string());
  }
  return csv;
}

WrittenHistory WriteHistory(const History& history, const std::filesystem::path& outdir) {
  WrittenHistory written{outdir / "history.csv", outdir / "history.html", outdir / "history.pdf"};
  OutputSet outputs;
  outputs.CreateFolder(outdir);
  const std::filesystem::path csv_temporary = outputs.Stage(written.csv);
  const std::filesystem::path html_temporary = outputs.Stage(written.html);
  const std::filesystem::path pdf_temporary = outputs.Stage(written.pdf);
  internal::RenderPdfPages(pdf_temporary, Title(history),
                           [&](internal::PdfFlow& pdf) { LayoutHistoryPdf(pdf, history); });
  WriteFileAtomically(html_temporary, RenderHistoryHtml(history));
  WriteFileAtomically(csv_temporary, HistoryCsv(history));
  outputs.Commit();
  return written;
}

}  // namespace arcwheel::reports
