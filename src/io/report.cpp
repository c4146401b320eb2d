#include "drt/io/report.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

#include "drt/util/atomic_file.h"

namespace drt {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPage = "index.html";
constexpr const char* kRecordExtension = ".case";
// Small renders (a golden test's are 96 pixels wide) are shown enlarged by a whole factor, so
// that pixels stay sharp squares, to about this width.
constexpr int kShownWidth = 288;

// A case as recorded beside the page: what the page shows, as text. The images are files.
using Record = std::map<std::string, std::string>;

// A file name for the case: its name made safe, with a hash of the name against collisions.
std::string case_id(const std::string& name) {
    std::string id;
    for (const unsigned char c : name) {
        id += std::isalnum(c) || c == '-' || c == '_' ? static_cast<char>(c) : '_';
    }
    std::uint32_t hash = 2166136261u;  // FNV-1a
    for (const unsigned char c : name) hash = (hash ^ c) * 16777619u;
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, "-%08x", hash);
    return id.substr(0, 80) + suffix;
}

std::string escape_line(const std::string& s) {
    std::string out;
    for (const char c : s) {
        if (c == '\\')
            out += "\\\\";
        else if (c == '\n')
            out += "\\n";
        else
            out += c;
    }
    return out;
}

std::string unescape_line(const std::string& s) {
    std::string out;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '\\' && i + 1 < s.size()) {
            out += s[++i] == 'n' ? '\n' : s[i];
        } else {
            out += s[i];
        }
    }
    return out;
}

std::string html(const std::string& s) {
    std::string out;
    for (const char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

// Holds an exclusive lock on the report folder while the page and its records change, so that
// parallel test processes adding cases do not lose each other's.
class FolderLock {
  public:
    explicit FolderLock(const fs::path& dir) {
        fs::create_directories(dir);
        fd_ = ::open((dir / ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd_ < 0) throw FileWriteError((dir / ".lock").string() + ": cannot create lock file");
        while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
        }
    }
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;
    ~FolderLock() { ::close(fd_); }  // closing releases the lock

  private:
    int fd_ = -1;
};

// 8-bit images hold sRGB-encoded values / 255; writing them as PNG encodes again, so they are
// decoded first and come out as the bytes they were.
Image for_display(const Image& image, bool linear) {
    if (linear) return image;
    Image shown = image;
    for (float& v : shown.rgb) v = static_cast<float>(decode_srgb(v));
    return shown;
}

void write_case(const fs::path& dir, const ReportCase& c) {
    const std::string id = case_id(c.name);
    Record r{{"name", c.name},
             {"reference_file", c.reference_file},
             {"render_file", c.render_file},
             {"failed", c.failed ? "1" : "0"},
             {"note", c.note}};
    const auto image = [&](const std::string& kind, const std::optional<Image>& img, bool linear) {
        const fs::path file = dir / (id + "." + kind + ".png");
        fs::remove(file);
        if (!img) return;
        write_image(for_display(*img, linear), file);
        r[kind] = file.filename().string();
        r[kind + "_size"] = std::to_string(img->width) + " " + std::to_string(img->height);
    };
    image("reference", c.reference, c.linear);
    image("render", c.render, c.linear);
    std::optional<Image> diff;
    if (c.reference && c.render && c.reference->width == c.render->width &&
        c.reference->height == c.render->height) {
        diff = difference_image(*c.render, *c.reference);
    }
    image("diff", diff, true);  // false colours are stored linear
    if (c.measures) {
        r["rmse"] = format_measure(c.measures->rmse);
        r["psnr"] = format_measure(c.measures->psnr);
        r["ssim"] = format_measure(c.measures->ssim);
        r["max"] = format_measure(c.measures->max_abs);
        r["nonfinite"] = std::to_string(c.measures->nonfinite);
    }
    std::string text;
    for (const auto& [key, value] : r) text += key + " " + escape_line(value) + "\n";
    replace_file(dir / (id + kRecordExtension), text);
}

void remove_case_files(const fs::path& record) {
    const std::string id = record.stem().string();
    for (const char* kind : {".reference.png", ".render.png", ".diff.png"}) {
        fs::remove(record.parent_path() / (id + kind));
    }
    fs::remove(record);
}

std::vector<fs::path> records_in(const fs::path& dir) {
    std::vector<fs::path> records;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
        if (entry.path().extension() == kRecordExtension) records.push_back(entry.path());
    }
    return records;
}

Record read_record(const fs::path& file) {
    Record r;
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);) {
        const std::size_t space = line.find(' ');
        if (space != std::string::npos)
            r[line.substr(0, space)] = unescape_line(line.substr(space + 1));
    }
    return r;
}

// Worst first: failures, then cases that could not be measured, then by RMSE, largest (or NaN)
// first; by name among equals.
bool worse(const Record& a, const Record& b) {
    const auto key = [](const Record& r) {
        const auto it = r.find("rmse");
        double rmse = it == r.end() ? INFINITY : std::strtod(it->second.c_str(), nullptr);
        if (std::isnan(rmse)) rmse = INFINITY;
        return std::make_tuple(r.at("failed") != "1", it != r.end(), -rmse);
    };
    const auto ka = key(a), kb = key(b);
    return ka != kb ? ka < kb : a.at("name") < b.at("name");
}

std::string figure(const Record& r, const std::string& kind, const std::string& caption,
                   const std::string& file) {
    std::ostringstream s;
    s << "<figure class=\"" << kind << "\">";
    const auto image = r.find(kind);
    if (image != r.end()) {
        int w = 1, h = 1;
        std::istringstream(r.at(kind + "_size")) >> w >> h;
        const int zoom = std::max(1, kShownWidth / std::max(w, 1));
        s << "<img src=\"" << html(image->second) << "\" width=\"" << w * zoom << "\" height=\""
          << h * zoom << "\" alt=\"" << caption << "\">";
    } else {
        s << "<div class=\"missing\">no image</div>";
    }
    s << "<figcaption>" << caption;
    if (!file.empty()) s << "<br><code>" << html(file) << "</code>";
    return s.str() + "</figcaption></figure>";
}

std::string page(const std::string& title, std::vector<Record> cases) {
    std::sort(cases.begin(), cases.end(), worse);
    const auto failed = std::count_if(cases.begin(), cases.end(),
                                      [](const Record& r) { return r.at("failed") == "1"; });
    const auto value = [](const Record& r, const std::string& key) {
        const auto it = r.find(key);
        return it == r.end() ? std::string("–") : it->second;
    };
    std::ostringstream s;
    s << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
      << html(title) << "</title>\n<style>\n"
      << "body{font:14px/1.4 sans-serif;margin:1.5em;color:#222;background:#f6f6f6}\n"
         "h1{font-size:1.4em;margin:0 0 .3em}h2{font-size:1.1em;margin:.2em 0}\n"
         "table{border-collapse:collapse;background:#fff}\n"
         "th,td{padding:.15em .6em;border-bottom:1px solid #ddd;text-align:right}\n"
         "th:first-child,td:first-child{text-align:left}\n"
         ".case{background:#fff;border:1px solid #ccc;border-left:6px solid #2a2;"
         "padding:.4em 1em .8em;margin:1em 0}\n"
         ".case.failed{border-left-color:#c22}\n"
         ".verdict{font-weight:bold;color:#2a2}.failed .verdict{color:#c22}\n"
         ".note{margin:.2em 0 .5em;white-space:pre-wrap}\n"
         ".images{display:flex;flex-wrap:wrap;gap:1em;margin-top:.6em}\n"
         "figure{margin:0;max-width:100%}figcaption{font-size:.9em;color:#555}\n"
         "img{display:block;max-width:100%;height:auto;image-rendering:pixelated;"
         "background:#000}\n"
         ".missing{width:12em;height:8em;display:flex;align-items:center;justify-content:center;"
         "background:#eee;color:#888}\n"
         "code{font-size:.85em;word-break:break-all}\n"
         "</style>\n</head>\n<body>\n<h1>"
      << html(title) << "</h1>\n<p class=\"summary\">" << cases.size() << " case"
      << (cases.size() == 1 ? "" : "s") << ", " << failed
      << " failed; worst first. Images are shown sRGB-encoded and clamped to [0, 1], enlarged "
         "without smoothing. The difference is drt compare's: black where equal, then blue, "
         "green, yellow, red at the case's largest per-pixel error (RMS over the channels). "
         "RMSE and PSNR are over all pixels and channels of the stored values; SSIM is the mean "
         "structural similarity of the luminance (docs/usage.md).</p>\n"
      << "<table class=\"overview\">\n<tr><th>case</th><th>result</th><th>RMSE</th><th>PSNR</th>"
         "<th>SSIM</th></tr>\n";
    for (const Record& r : cases) {
        const std::string id = case_id(r.at("name"));
        s << "<tr><td><a href=\"#" << id << "\">" << html(r.at("name")) << "</a></td><td>"
          << (r.at("failed") == "1" ? "FAIL" : "pass") << "</td><td>" << value(r, "rmse")
          << "</td><td>" << value(r, "psnr") << "</td><td>" << value(r, "ssim") << "</td></tr>\n";
    }
    s << "</table>\n";
    for (const Record& r : cases) {
        const bool fail = r.at("failed") == "1";
        s << "<section class=\"case" << (fail ? " failed" : "") << "\" id=\""
          << case_id(r.at("name")) << "\" data-reference=\"" << html(r.at("reference_file"))
          << "\" data-render=\"" << html(r.at("render_file")) << "\">\n<h2><span class=\"verdict\">"
          << (fail ? "FAIL" : "pass") << "</span> " << html(r.at("name")) << "</h2>\n";
        if (!r.at("note").empty()) s << "<p class=\"note\">" << html(r.at("note")) << "</p>\n";
        s << "<table class=\"measures\"><tr><th>RMSE</th><th>PSNR (dB)</th><th>SSIM</th>"
             "<th>largest difference</th><th>non-finite values</th></tr>\n<tr><td class=\"rmse\">"
          << value(r, "rmse") << "</td><td class=\"psnr\">" << value(r, "psnr")
          << "</td><td class=\"ssim\">" << value(r, "ssim") << "</td><td class=\"max\">"
          << value(r, "max") << "</td><td class=\"nonfinite\">" << value(r, "nonfinite")
          << "</td></tr></table>\n<div class=\"images\">"
          << figure(r, "reference", "reference", r.at("reference_file"))
          << figure(r, "render", "render", r.at("render_file"))
          << figure(r, "diff", "difference", "") << "</div>\n</section>\n";
    }
    s << "</body>\n</html>\n";
    return s.str();
}

// Rewrites the page from the records in `dir`, or removes it when there are none.
fs::path write_page(const fs::path& dir, const std::string& title) {
    std::vector<Record> cases;
    for (const fs::path& file : records_in(dir)) {
        Record r = read_record(file);
        if (r.contains("name") && r.contains("failed") && r.contains("note") &&
            r.contains("reference_file") && r.contains("render_file")) {
            cases.push_back(std::move(r));
        }
    }
    const fs::path path = dir / kPage;
    if (cases.empty()) {
        fs::remove(path);
    } else {
        replace_file(path, page(title, std::move(cases)));
    }
    return path;
}

}  // namespace

ReportCase compare_case(std::string name, std::string reference_file, std::string render_file,
                        std::optional<Image> reference, std::optional<Image> render, bool linear) {
    ReportCase c{std::move(name),
                 std::move(reference_file),
                 std::move(render_file),
                 false,
                 "",
                 std::move(reference),
                 std::move(render),
                 linear,
                 std::nullopt};
    if (c.reference && c.render) {
        try {
            c.measures = compare_images(*c.render, *c.reference);
        } catch (const ImageError& e) {
            c.note = e.what();
        }
    }
    return c;
}

fs::path write_report(const fs::path& dir, const std::string& title,
                      const std::vector<ReportCase>& cases) {
    const FolderLock lock(dir);
    for (const fs::path& record : records_in(dir)) remove_case_files(record);
    for (const ReportCase& c : cases) write_case(dir, c);
    return write_page(dir, title);
}

fs::path add_report_case(const fs::path& dir, const std::string& title, const ReportCase& c) {
    const FolderLock lock(dir);
    write_case(dir, c);
    return write_page(dir, title);
}

void remove_report_case(const fs::path& dir, const std::string& title, const std::string& name) {
    if (!fs::exists(dir / (case_id(name) + kRecordExtension))) return;
    const FolderLock lock(dir);
    remove_case_files(dir / (case_id(name) + kRecordExtension));
    write_page(dir, title);
}

}  // namespace drt
