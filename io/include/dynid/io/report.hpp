// dynid/io/report.hpp -- the HTML report of a results folder written by `dynid run` (docs/report.md): one
// self-contained page (figures embedded as PNG data) with a section per step.
#pragma once

#include <string>

namespace dynid {

/// The name of the manifest `dynid run` writes into its results folder.
inline constexpr const char* kRunManifest = "run.json";

/// Builds the report page from `dir` (a folder with run.json and the steps' JSON and PNG files). Throws
/// InputError naming the file when the manifest or a step's JSON is missing or malformed.
std::string html_report(const std::string& dir);

}  // namespace dynid
