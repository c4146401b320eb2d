#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "cli_render.h"
#include "drt/io/compare.h"
#include "drt/io/image.h"
#include "drt/io/report.h"
#include "drt/util/text.h"

namespace drt::cli {

namespace fs = std::filesystem;

namespace {

// 130 and 143 are SIGINT's and SIGTERM's (128 + the signal).
std::string_view status_word(int status) {
    if (status == kOk) return "ok";
    if (status == kFailed) return "failed";
    if (status == kBadInput) return "bad input";
    return "interrupted";
}

}  // namespace

void print_summary(const std::vector<SceneOutcome>& outcomes, std::ostream& out) {
    out << std::left << std::setw(32) << "scene" << std::right << std::setw(11) << "size"
        << std::setw(9) << "samples" << std::setw(10) << "seconds" << std::setw(10) << "Mrays/s"
        << "  status\n";
    for (const SceneOutcome& o : outcomes) {
        std::ostringstream size;
        if (o.width > 0) size << o.width << "x" << o.height;
        out << std::left << std::setw(32) << printable(fs::path(o.scene).filename().string())
            << std::right << std::setw(11) << size.str() << std::setw(9)
            << (o.samples ? std::to_string(o.samples) : "") << std::fixed << std::setprecision(2)
            << std::setw(10) << o.seconds << std::setw(10) << o.mrays_per_second
            << std::defaultfloat << "  " << status_word(o.status) << "\n";
    }
}

bool is_folder_target(const std::string& output) {
    std::error_code ignored;  // a name that cannot be examined is not a folder
    return !output.empty() && (output.back() == '/' || fs::is_directory(output, ignored));
}

void BatchReport::add_to(CLI::App& app) {
    CLI::Option* refs =
        app.add_option("--reference-dir", reference_dir,
                       "Batch report: the folder of reference images, one per output name");
    app.add_flag("--report", wanted,
                 "Batch: compare each image with --reference-dir's and write DIR/report/"
                 "index.html, worst first")
        ->needs(refs);
    app.add_option("--max-rmse", max_rmse,
                   "Batch report: a case fails when its RMSE exceeds X (default 0: any change)")
        ->check(finite_non_negative())
        ->needs(refs);
}

int BatchReport::write(const std::vector<SceneOutcome>& outcomes, const fs::path& folder,
                       bool quiet, std::ostream& err) const {
    int status = kOk;
    std::vector<ReportCase> cases;
    for (const SceneOutcome& o : outcomes) {
        const fs::path reference_file = fs::path(reference_dir) / o.output.filename();
        std::optional<Image> reference, render;
        std::string note;
        try {
            reference = read_image(reference_file);
        } catch (const ImageError& e) {
            note = std::string("no reference: ") + e.what();
            status = std::max(status, kBadInput);
        }
        if (o.status == kOk) {
            try {
                render = read_image(o.output);
            } catch (const ImageError& e) {
                note += (note.empty() ? "" : "\n") + std::string(e.what());
                status = std::max(status, kFailed);
            }
        } else {
            note += (note.empty() ? "" : "\n") + std::string("the render failed (status ") +
                    std::to_string(o.status) + ")";
        }
        ReportCase c = compare_case(o.output.stem().string(), reference_file.string(),
                                    o.output.string(), std::move(reference), std::move(render),
                                    is_linear(format_for_path(o.output)));
        if (c.measures && !(c.measures->rmse <= max_rmse)) {
            note += "rmse " + format_measure(c.measures->rmse) + " exceeds --max-rmse " +
                    format_measure(max_rmse);
            status = std::max(status, kFailed);
        } else if (!c.measures && reference && render) {
            status = std::max(status, kBadInput);  // sizes differ: compare_case says so
        }
        c.failed = o.status != kOk || !c.measures || !(c.measures->rmse <= max_rmse);
        c.note = note + (note.empty() || c.note.empty() ? "" : "\n") + c.note;
        cases.push_back(std::move(c));
    }
    try {
        const fs::path page = write_report(folder / "report", "drt batch report", cases);
        if (!quiet) err << "drt: wrote report " << printable(page.string()) << "\n";
    } catch (const std::exception& e) {
        err << "drt: report: " << printable(e.what()) << "\n";
        status = std::max(status, kFailed);
    }
    return status;
}

}  // namespace drt::cli
