// dynid/io/report.hpp: the report page of a results folder. What `dynid run` writes is checked in a browser by
// ctest report.browser; here, folders that are not what it writes: missing keys give "-" cells (not a crash),
// malformed manifests and files outside the folder give errors naming the manifest.
#include <gtest/gtest.h>

#include <filesystem>

#include "dynid/io/report.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

using test::ErrorOf;


class Report : public ::testing::Test {
 protected:
  void Write(const std::string& f, const std::string& text) const { scratch_.write(f, text); }
  std::string Dir() const { return scratch_.dir().string(); }
  const test::ScratchDir scratch_{"report"};
};

TEST_F(Report, MissingKeysGiveDashesNotACrash) {
  Write("run.json", R"({"case": "c", "steps": [{"name": "modal", "json": "modal.json"}, {"name": "detect", "json": "detect.json"},
                       {"name": "update", "json": "update.json"}, {"name": "discover", "json": "discover.json"},
                       {"name": "identify", "json": "identify.json"}, {"name": "detect", "json": "absent.json", "exit_code": 2}]})");
  Write("modal.json", R"({"modes": [{"index": 1}]})");
  Write("detect.json", R"({"modes": {"model_hz": [1.0, 2.0]}})");
  Write("update.json", R"({"frequencies_hz": {"measured": [3.0]}})");
  Write("discover.json", R"({"verdict": "consistent", "fit": {}})");
  Write("identify.json", R"({"modes": [{"frequency_hz": 4.5}]})");
  const std::string html = html_report(Dir());
  EXPECT_HAS(html, "<td>1</td><td>1</td><td>-</td><td>-</td><td>-</td>");  // detect: mode 1, model 1 Hz, rest unknown
  EXPECT_HAS(html, "Verdict: consistent");
  EXPECT_HAS(html, "This step ended with exit code 2");
  EXPECT_HAS(html, "No results (absent.json is missing)");
  EXPECT_HAS(html, "data-images=\"0\"");
}

TEST_F(Report, MalformedManifestsAreNamed) {
  EXPECT_HAS(ErrorOf([&] { html_report(Dir()); }), "no run.json here; make the folder with `dynid run CASE --out");
  Write("run.json", R"({"steps": [1, 2]})");
  EXPECT_HAS(ErrorOf([&] { html_report(Dir()); }), "run.json: not a dynid run manifest");
  Write("run.json", R"({"steps": [{"name": "modal", "json": "../modal.json"}]})");
  EXPECT_HAS(ErrorOf([&] { html_report(Dir()); }), "step file '../modal.json' must be a file name inside the results folder");
  Write("run.json", R"({"steps": [{"name": "modal", "json": "modal.json"}]})");
  Write("modal.json", "{not json");
  EXPECT_HAS(ErrorOf([&] { html_report(Dir()); }), "modal.json: not valid JSON");
  Write("modal.json", "[1, 2]");
  EXPECT_HAS(ErrorOf([&] { html_report(Dir()); }), "modal.json: not the results JSON of dynid modal");
}

}  // namespace
}  // namespace dynid
