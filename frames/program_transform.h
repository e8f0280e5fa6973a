#pragma once
// Whole-file transforms: a toolpath CSV (formats.md section 6), an ISO G-code program or a PMAC
// motion program, rewritten into another frame with every other byte kept.
//
// Toolpath CSV: the columns xw_mm,yw_mm,zw_mm and x_mm,y_mm,z_mm are points (transformed), nx,ny,nz
// a direction (rotated, not translated; renormalised); each rewritten number is written in shortest
// round-trip form. Comment lines, the header, other columns and line endings are untouched.
// G-code: X/Y/Z words of G0/G1 moves in absolute mode (G90). Refused, with the line number: G91
// incremental, G2/G3 arcs, G20 inches, G28/G30/G53/G92 and G68/G51 (machine positions, offsets,
// rotation, scaling), canned cycles, A/B/C rotary words, I/J/K arc words, a coordinate word without
// a literal number. Comments in parentheses or after ';' are untouched.
// PMAC: the same words on lines between OPEN PROG and CLOSE (LINEAR, RAPID and SPLINE moves);
// refused: INC, CIRCLE1/CIRCLE2, PVT, A/B/C words, X/Y/Z given by an expression.
//
// A move may give only some axes (modal coordinates). After a rotation every target axis can depend
// on every source axis, so a line writes each target axis whose word is present or whose source
// axes changed on that line; it is refused if such an axis depends on a source axis not yet known.
// Rewritten machine-program numbers are written with a fixed number of digits after the point
// (ProgramTransformOptions::decimals), as the toolpath writer does; the point is never dropped.

#include <filesystem>
#include <string>
#include <string_view>

#include "frames/transform.h"

namespace arcwheel::frames {

enum class ProgramKind { kToolpathCsv, kGcode, kPmac };

// By extension (.csv; .pmc/.pmac; .nc/.ngc/.gcode/.tap/.iso/.cnc), else by content (OPEN PROG
// means PMAC, a header with x_mm means toolpath CSV), else G-code.
[[nodiscard]] ProgramKind DetectProgramKind(const std::filesystem::path& path, std::string_view text);
// "csv", "gcode", "pmac" -> kind; throws Error{kInvalidOption}.
[[nodiscard]] ProgramKind ParseProgramKind(std::string_view name);

struct ProgramTransformOptions {
  // Digits after the point of rewritten G-code and PMAC numbers, in [1, 12]; -1: the most that the
  // input's X/Y/Z words have (4 if none has a point), so the program keeps its own resolution.
  int decimals = -1;
  // Empty when valid, else the violation with its value, named by the flag of `arcwheel transform
  // apply`: "--decimals = 13 violates -1 or [1, 12]".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct ProgramTransformResult {
  std::string text;
  int points_transformed = 0;  // CSV point triples or program moves rewritten
  int lines_changed = 0;
};

// Rewrites `text` (the contents of `source_name`) with `transform` applied to every point.
// Throws Error{kBadInput, "frames.program_transform"} naming the file and line for anything it
// cannot transform faithfully; nothing is returned in that case.
[[nodiscard]] ProgramTransformResult TransformProgram(std::string_view text, ProgramKind kind,
                                                      const Transform& transform,
                                                      const std::string& source_name,
                                                      const ProgramTransformOptions& options = {});

}  // namespace arcwheel::frames
