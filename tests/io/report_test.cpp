// Regression reports: the page and its images as files, and the page as a browser shows it.
#include "drt/io/report.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "run_drt.h"

namespace drt {
namespace {

namespace fs = std::filesystem;
using test::read_bytes, test::write_bytes, test::run_drt, test::Outcome;

class ReportTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("drt_report_test_" + std::to_string(getpid()) + "_" +
                                            info->test_suite_name() + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(dir_);
    }
    fs::path file(const std::string& name) const { return dir_ / name; }

    fs::path dir_;
};

Image ramp(int w, int h, float offset) {
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) image.set(x, y, {x / double(w) + offset, y / double(h), 0.25});
    }
    return image;
}

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) {
        ++n;
    }
    return n;
}

TEST_F(ReportTest, PageShowsEveryCaseWorstFirstWithItsMeasuresAndNoScriptOrNetwork) {
    const Image reference = ramp(8, 4, 0);
    std::vector<ReportCase> cases;
    cases.push_back(compare_case("same", "r.pfm", "a.pfm", reference, reference, true));
    cases.push_back(
        compare_case("slightly off", "r.pfm", "b.pfm", reference, ramp(8, 4, 0.01f), true));
    cases.push_back(compare_case("far off", "r.pfm", "c.pfm", reference, ramp(8, 4, 0.2f), true));
    cases.push_back(compare_case("no render", "r.pfm", "d.pfm", reference, std::nullopt, true));
    cases[3].failed = true;
    cases[3].note = "the render failed <badly> & \"loudly\"";
    const fs::path page = write_report(dir_, "title <1>", cases);
    EXPECT_EQ(page, dir_ / "index.html");
    const std::string html = read_bytes(page);

    // Failures first, then by RMSE, largest first.
    const std::size_t none = html.find("<h2><span class=\"verdict\">FAIL</span> no render");
    const std::size_t far = html.find("</span> far off</h2>");
    const std::size_t slight = html.find("</span> slightly off</h2>");
    const std::size_t same = html.find("<h2><span class=\"verdict\">pass</span> same</h2>");
    ASSERT_NE(none, std::string::npos) << html;
    ASSERT_NE(same, std::string::npos) << html;
    EXPECT_LT(none, far);
    EXPECT_LT(far, slight);
    EXPECT_LT(slight, same);

    // The measures as drt compare prints them; 0.2 off in one channel of three: rmse 0.2/sqrt(3).
    const Comparison c = compare_images(ramp(8, 4, 0.2f), reference);
    EXPECT_NE(html.find("<td class=\"rmse\">" + format_measure(c.rmse) + "</td>"),
              std::string::npos);
    EXPECT_EQ(format_measure(c.rmse), "0.11547");
    EXPECT_NE(html.find("<td class=\"psnr\">inf</td><td class=\"ssim\">1</td>"), std::string::npos);
    EXPECT_NE(html.find("<title>title &lt;1&gt;</title>"), std::string::npos);
    EXPECT_NE(html.find("the render failed &lt;badly&gt; &amp; &quot;loudly&quot;"),
              std::string::npos);
    EXPECT_NE(html.find("4 cases, 1 failed"), std::string::npos);
    EXPECT_EQ(html.find("<script"), std::string::npos);
    EXPECT_EQ(html.find("http"), std::string::npos);
    // Three images for each full case, two for the one without a render; all beside the page.
    EXPECT_EQ(count(html, "<img src=\""), 3u * 3 + 1);
    int pngs = 0;
    for (const auto& e : fs::directory_iterator(dir_)) pngs += e.path().extension() == ".png";
    EXPECT_EQ(pngs, 10);
    // 8 pixels wide is shown 36 times as large (288 pixels), sharp.
    EXPECT_NE(html.find("width=\"288\" height=\"144\""), std::string::npos);
}

TEST_F(ReportTest, EightBitImagesAreShownAsTheirOwnBytes) {
    Image image(16, 1);
    for (int x = 0; x < 16; ++x) image.set(x, 0, {x / 15.0, 1 - x / 15.0, (x * 7 % 16) / 15.0});
    write_image(image, file("a.png"));
    const Image stored = read_image(file("a.png"));  // sRGB-encoded values / 255
    write_report(dir_ / "r", "t", {compare_case("a", "a.png", "a.png", stored, stored, false)});
    for (const auto& e : fs::directory_iterator(dir_ / "r")) {
        if (e.path().string().ends_with(".reference.png")) {
            EXPECT_EQ(read_image(e.path()).rgb, stored.rgb);
        }
    }
}

TEST_F(ReportTest, CasesAddedAtOnceByManyProcessesAreAllKeptAndRemovingTheLastRemovesThePage) {
    const Image reference = ramp(4, 4, 0);
    std::vector<pid_t> children;
    for (int k = 0; k < 6; ++k) {
        const pid_t pid = fork();
        if (pid == 0) {
            const ReportCase c = compare_case("case " + std::to_string(k), "r", "a", reference,
                                              ramp(4, 4, 0.01f * k), true);
            add_report_case(dir_, "t", c);
            _exit(0);
        }
        children.push_back(pid);
    }
    for (const pid_t pid : children) {
        int status = 0;
        waitpid(pid, &status, 0);
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    std::string html = read_bytes(dir_ / "index.html");
    EXPECT_NE(html.find("6 cases"), std::string::npos) << html;

    // Adding a case of an existing name replaces it.
    ReportCase again = compare_case("case 3", "r", "a", reference, reference, true);
    again.failed = true;
    add_report_case(dir_, "t", again);
    html = read_bytes(dir_ / "index.html");
    EXPECT_NE(html.find("6 cases, 1 failed"), std::string::npos) << html;

    for (int k = 0; k < 6; ++k) remove_report_case(dir_, "t", "case " + std::to_string(k));
    EXPECT_FALSE(fs::exists(dir_ / "index.html"));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);  // .lock
}

// ---- in a browser -----------------------------------------------------------------------------

bool have_chromium() {
    return std::system("command -v chromium >/dev/null 2>&1") == 0;
}

// Loads a copy of the page, with a script that waits for every image and then lists how each
// decoded and the numbers each case shows, in headless Chromium, and returns that list: lines
// "images N", "broken SRC…", then per case "RESULT|RENDER|REFERENCE|RMSE|PSNR|SSIM".
std::vector<std::string> read_in_browser(const fs::path& page, const fs::path& scratch) {
    std::string html = read_bytes(page);
    const std::string script = R"(<script>
window.addEventListener('load', () => {
  const images = [...document.images];
  const lines = ['images ' + images.length,
                 'broken ' + images.filter(i => !(i.complete && i.naturalWidth > 0))
                                   .map(i => i.getAttribute('src')).join(' ')];
  for (const s of document.querySelectorAll('section.case')) {
    lines.push([s.classList.contains('failed') ? 'FAIL' : 'pass', s.dataset.render,
                s.dataset.reference, s.querySelector('.rmse').textContent,
                s.querySelector('.psnr').textContent, s.querySelector('.ssim').textContent].join('|'));
  }
  const out = document.createElement('pre');
  out.id = 'drt-check';
  out.textContent = '\n' + lines.join('\n') + '\n';
  document.body.appendChild(out);
});
</script>
)";
    html.insert(html.rfind("</body>"), script);
    const fs::path copy = page.parent_path() / "check.html";
    write_bytes(copy, html);
    const fs::path profile = scratch / "chromium-profile";
    fs::create_directories(profile);
    const std::string dom = test::shell_output(
        "timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
        "--disable-background-networking --disable-component-update --disable-sync "
        "--user-data-dir=" +
        profile.string() + " --dump-dom 'file://" + copy.string() + "' 2>/dev/null");
    fs::remove_all(profile);
    fs::remove(copy);
    const std::size_t start = dom.find("<pre id=\"drt-check\">");
    const std::size_t end = dom.find("</pre>", start);
    if (start == std::string::npos || end == std::string::npos) {
        ADD_FAILURE() << "the page's check did not run; chromium printed:\n" << dom;
        return {};
    }
    std::vector<std::string> lines;
    std::istringstream text(dom.substr(start, end - start));
    for (std::string line; std::getline(text, line);) {
        if (!line.empty() && line.find("<pre") == std::string::npos) lines.push_back(line);
    }
    return lines;
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> parts;
    std::istringstream in(s);
    for (std::string part; std::getline(in, part, sep);) parts.push_back(part);
    return parts;
}

// The value of `key=` in drt compare's line.
std::string field(const std::string& line, const std::string& key) {
    const std::size_t at = line.find(key + "=");
    if (at == std::string::npos) return "(no " + key + ")";
    const std::size_t start = at + key.size() + 1;
    return line.substr(start, line.find_first_of(" \n", start) - start);
}

// Every image decodes in a real browser and every number on the page is drt compare's for the
// two files the case names.
void expect_page_matches_compare(const fs::path& page, const fs::path& cwd, std::size_t cases,
                                 std::size_t failed) {
    const std::vector<std::string> lines = read_in_browser(page, cwd);
    ASSERT_EQ(lines.size(), 2 + cases) << page;
    EXPECT_EQ(lines[0], "images " + std::to_string(3 * cases));
    EXPECT_EQ(lines[1], "broken ");
    std::size_t failures = 0;
    for (std::size_t i = 2; i < lines.size(); ++i) {
        const std::vector<std::string> c = split(lines[i], '|');
        ASSERT_EQ(c.size(), 6u) << lines[i];
        failures += c[0] == "FAIL";
        const Outcome compare = run_drt({"compare", c[1], c[2]}, cwd);
        ASSERT_EQ(compare.status, 0) << compare.err;
        EXPECT_EQ(c[3], field(compare.out, "rmse")) << lines[i];
        EXPECT_EQ(c[4], field(compare.out, "psnr")) << lines[i];
        EXPECT_EQ(c[5], field(compare.out, "ssim")) << lines[i];
    }
    EXPECT_EQ(failures, failed);
}

TEST_F(ReportTest, CompareReportInABrowser) {
    if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (tools/install-deps.sh)";
    write_image(ramp(40, 30, 0), file("reference.exr"));
    write_image(ramp(40, 30, 0.05f), file("render.exr"));
    const Outcome r = run_drt(
        {"compare", "render.exr", "reference.exr", "--max-rmse", "0.01", "--report", "cmp"}, dir_);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("drt compare: wrote report cmp/index.html"), std::string::npos) << r.err;
    expect_page_matches_compare(file("cmp/index.html"), dir_, 1, 1);
}

TEST_F(ReportTest, BatchReportInABrowser) {
    if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (tools/install-deps.sh)";
    const std::string scenes = std::string(DRT_SOURCE_DIR) + "/scenes/";
    const std::vector<std::string> batch{scenes + "example.xml", scenes + "figures/aa-1spp.xml",
                                         scenes + "figures/glossy-n10.xml", "--scale", "0.1"};
    std::vector<std::string> refs = batch, again = batch;
    refs.insert(refs.end(), {"-q", "-o", "ref/"});
    ASSERT_EQ(run_drt(refs, dir_).status, 0);
    // The aa-1spp figure has one sample per pixel: no noise, so a new seed changes nothing.
    again.insert(again.end(), {"--seed", "99", "-o", "out/", "--report", "--reference-dir", "ref",
                               "--max-rmse", "0.001"});
    const Outcome r = run_drt(again, dir_);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("drt: wrote report out/report/index.html"), std::string::npos) << r.err;
    expect_page_matches_compare(file("out/report/index.html"), dir_, 3, 2);
}

}  // namespace
}  // namespace drt
