#pragma once
// What a figure's reader sees of its text: in gnuplot's enhanced mode `_` subscripts one character, so a title
// or label holding a name such as `T_winding` reads as T with the subscript w followed by "inding". A script
// written by our figures must brace such subscripts (`T_{winding}`) or turn enhanced mode off for that text.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace rpem::test {

/// The titles and labels of a gnuplot script that enhanced mode would misprint: a `_` or `^` followed by more
/// than one letter or digit without braces. Lines with `noenhanced`, and everything after
/// `set termoption noenhanced`, are plain text and not checked.
inline std::vector<std::string> misprinted_gnuplot_text(const std::string& script) {
  static const std::regex text(R"re((?:title|\bt|xlabel|ylabel|y2label|cblabel|label)\s+('[^']*'|"[^"]*"))re");
  static const std::regex unbraced(R"re([_^][A-Za-z0-9]{2,})re");
  std::vector<std::string> found;
  std::istringstream lines(script);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("set termoption noenhanced") != std::string::npos) break;
    if (line.find("noenhanced") != std::string::npos) continue;
    for (auto m = std::sregex_iterator(line.begin(), line.end(), text); m != std::sregex_iterator(); ++m) {
      const std::string quoted = (*m)[1].str();
      if (std::regex_search(quoted, unbraced)) found.push_back(quoted);
    }
  }
  return found;
}

/// misprinted_gnuplot_text() of every .gp script in a directory, each prefixed with its file's name.
inline std::vector<std::string> misprinted_gnuplot_text_in(const std::filesystem::path& dir) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".gp") continue;
    std::ifstream in(entry.path());
    const std::string script((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (const std::string& s : misprinted_gnuplot_text(script))
      found.push_back(entry.path().filename().string() + ": " + s);
  }
  return found;
}

}  // namespace rpem::test
