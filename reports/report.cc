#include "reports/report.h"

#include "core/atomic_file.h"
#include "reports/report_inputs.h"

namespace arcwheel::reports {

WrittenReports WriteReports(const std::filesystem::path& outdir, const Tolerances& tolerances) {
  const ReportInputs inputs = ReadReportInputs(outdir);
  const ReportContent content = ComposeReport(inputs, tolerances);
  WrittenReports written{outdir / "report.html", outdir / "report.pdf", content.overall};
  OutputSet outputs;
  const std::filesystem::path html_temporary = outputs.Stage(written.html);
  const std::filesystem::path pdf_temporary = outputs.Stage(written.pdf);
  RenderPdf(content, pdf_temporary);
  WriteFileAtomically(html_temporary, RenderHtml(content));
  outputs.Commit();
  return written;
}

}  // namespace arcwheel::reports
