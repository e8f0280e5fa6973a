#include "reports/report.h"

#include "reports/html_page.h"
#include "reports/report_inputs.h"

namespace arcwheel::reports {

WrittenReports WriteReports(const std::filesystem::path& outdir, const Tolerances& tolerances) {
  const ReportInputs inputs = ReadReportInputs(outdir);
  const ReportContent content = ComposeReport(inputs, tolerances);
  WrittenReports written{outdir / "report.html", outdir / "report.pdf", content.overall};
  internal::WriteHtmlAndPdf(
      written.html, [&] { return RenderHtml(content); }, written.pdf,
      [&](const std::filesystem::path& pdf) { RenderPdf(content, pdf); });
  return written;
}

}  // namespace arcwheel::reports
