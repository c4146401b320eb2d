// Regression reports: one self-contained HTML page (index.html, its PNG images beside it, no
// scripts, nothing from the network) showing each case's reference, render and false-colour
// difference side by side with RMSE, PSNR and SSIM, worst first, failures marked.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "drt/io/compare.h"
#include "drt/io/image.h"

namespace drt {

// One comparison in a report.
struct ReportCase {
    std::string name;            // the heading; a case with the same name is replaced
    std::string reference_file;  // the files compared, as given (shown, and for drt compare)
    std::string render_file;
    bool failed = false;
    std::string note;                    // why it failed, or what else to know
    std::optional<Image> reference;      // absent when missing or unreadable
    std::optional<Image> render;         // absent when the render failed
    bool linear = true;                  // the images hold linear values, not 8-bit sRGB / 255
    std::optional<Comparison> measures;  // absent when the two could not be compared
};

// Measures a reference and a render of the same kind (both linear or both 8-bit) into a case:
// the measures, or a note saying why there are none.
ReportCase compare_case(std::string name, std::string reference_file, std::string render_file,
                        std::optional<Image> reference, std::optional<Image> render, bool linear);

// Writes the report in `dir` (created if missing) with exactly these cases, dropping any case an
// earlier report left there. Returns the page's path, dir/index.html. Throws ImageError or
// FileWriteError when a file cannot be written.
std::filesystem::path write_report(const std::filesystem::path& dir, const std::string& title,
                                   const std::vector<ReportCase>& cases);

// Adds one case to the report in `dir`, or replaces the case of its name, keeping the others;
// several processes may do this at once (a test suite's cases run in parallel). Returns the
// page's path.
std::filesystem::path add_report_case(const std::filesystem::path& dir, const std::string& title,
                                      const ReportCase& c);

// Takes the named case out of the report in `dir`, if it is there; the page goes when its last
// case does.
void remove_report_case(const std::filesystem::path& dir, const std::string& title,
                        const std::string& name);

}  // namespace drt
