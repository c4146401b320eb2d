#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <new>
#include <optional>
#include <sstream>
#include <string>

#include "cli_common.h"
#include "drt/io/compare.h"
#include "drt/io/image.h"
#include "drt/io/report.h"
#include "drt/util/text.h"

namespace drt::cli {

namespace fs = std::filesystem;

int compare_command(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
    CLI::App app{"Compare two images (.png, .bmp, .pfm, .exr) of equal size", "drt compare"};
    std::string a, b, diff;
    std::optional<double> max_rmse, min_psnr;
    app.add_option("A", a, "First image")->required();
    app.add_option("B", b, "Second image")->required();
    app.add_option("--max-rmse", max_rmse, "Exit 1 when the RMSE exceeds X")
        ->check(finite_non_negative());
    app.add_option("--min-psnr", min_psnr, "Exit 1 when the PSNR falls below Y (dB)");
    app.add_option("--diff", diff,
                   "Write a false-colour difference image to D (.png, .bmp, .pfm, .exr)");
    std::string report_dir;
    app.add_option("--report", report_dir,
                   "Write DIR/index.html showing B (the reference), A (the render) and their "
                   "difference with the measures");
    if (const auto status = parse_arguments(app, argc, argv, "drt compare", out, err))
        return *status;
    Comparison c;
    Image image_a, image_b;
    try {
        // Check every name before reading, so a typo costs nothing and writes nothing.
        const bool linear_a = is_linear(format_for_path(a));
        const bool linear_b = is_linear(format_for_path(b));
        if (!diff.empty()) format_for_path(diff);
        if (linear_a != linear_b) {
            // The measures are of the stored values, as always; said because linear floats
            // against sRGB-encoded bytes then measure the tone curve as much as the image.
            err << "drt compare: warning: " << printable(linear_a ? a : b)
                << " holds linear values and " << printable(linear_a ? b : a)
                << " sRGB-encoded 8-bit ones: the measures include the tone curve\n";
        }
        image_a = read_image(a);
        image_b = read_image(b);
        c = compare_images(image_a, image_b);
    } catch (const ImageError& e) {
        return report_failure(e, "drt compare", "", err);
    } catch (const std::bad_alloc& e) {  // any other failure reaches run_cli's last guard
        return report_failure(e, "drt compare", "", err);
    }
    out << comparison_fields(c) << "\n";
    int status = kOk;
    if (!diff.empty()) {
        try {
            write_image(difference_image(image_a, image_b), diff);
        } catch (const ImageError& e) {
            err << "drt compare: " << e.what() << "\n";
            status = kFailed;
        }
    }
    // Written as "not within" so that a NaN error (a NaN pixel) fails instead of passing.
    std::string verdict;
    if (max_rmse && !(c.rmse <= *max_rmse)) {
        verdict =
            "rmse " + format_measure(c.rmse) + " exceeds --max-rmse " + format_measure(*max_rmse);
    }
    if (min_psnr && !(c.psnr >= *min_psnr)) {
        verdict += (verdict.empty() ? "" : "\n") + std::string("psnr ") + format_measure(c.psnr) +
                   " is below --min-psnr " + format_measure(*min_psnr);
    }
    if (!verdict.empty()) {
        std::istringstream lines(verdict);
        for (std::string line; std::getline(lines, line);) err << "drt compare: " << line << "\n";
        status = kFailed;
    }
    if (!report_dir.empty()) {
        ReportCase rc{printable(a) + " against " + printable(b),
                      b,
                      a,
                      !verdict.empty(),
                      verdict,
                      std::move(image_b),
                      std::move(image_a),
                      is_linear(format_for_path(a)),
                      c};
        try {
            const fs::path page = write_report(report_dir, "drt compare", {rc});
            err << "drt compare: wrote report " << printable(page.string()) << "\n";
        } catch (const std::exception& e) {
            err << "drt compare: report: " << printable(e.what()) << "\n";
            status = kFailed;
        }
    }
    return status;
}

}  // namespace drt::cli
