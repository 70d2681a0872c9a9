#include "rpem/analysis/report_document.hpp"

#include <sstream>

namespace rpem::analysis {
namespace {

std::string escape_html(const std::string& s) {
  std::string out;
  for (char c : s) {
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

/// A table cell for Markdown: its pipes escaped.
std::string markdown_cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

/// Markdown's inline `code` and **bold** as HTML (the only inline markup the reports use).
std::string inline_html(const std::string& text) {
  const std::string s = escape_html(text);
  std::string out;
  bool code = false, bold = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '`') {
      out += code ? "</code>" : "<code>";
      code = !code;
    } else if (!code && s.compare(i, 2, "**") == 0) {
      out += bold ? "</b>" : "<b>";
      bold = !bold;
      ++i;
    } else {
      out += s[i];
    }
  }
  return out;
}

}  // namespace

void ReportDocument::heading(int level, const std::string& text) { blocks_.push_back({Kind::kHeading, level, {text}, {}}); }
void ReportDocument::paragraph(const std::string& text) { blocks_.push_back({Kind::kParagraph, 0, {text}, {}}); }
void ReportDocument::bullets(const std::vector<std::string>& items) { blocks_.push_back({Kind::kBullets, 0, items, {}}); }

void ReportDocument::table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  Block b{Kind::kTable, 0, {}, {header}};
  b.rows.insert(b.rows.end(), rows.begin(), rows.end());
  blocks_.push_back(std::move(b));
}

void ReportDocument::figure(const std::string& relative_path, const std::string& caption) {
  blocks_.push_back({Kind::kFigure, 0, {relative_path, caption}, {}});
}

std::string ReportDocument::markdown() const {
  std::ostringstream md;
  md << "# " << title_ << "\n\n";
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Kind::kHeading:
        md << std::string(static_cast<std::size_t>(b.level + 1), '#') << ' ' << b.text[0] << "\n\n";
        break;
      case Kind::kParagraph:
        md << b.text[0] << "\n\n";
        break;
      case Kind::kBullets:
        for (const std::string& item : b.text) md << "- " << item << '\n';
        md << '\n';
        break;
      case Kind::kTable:
        for (std::size_t r = 0; r < b.rows.size(); ++r) {
          md << '|';
          for (const std::string& cell : b.rows[r]) md << ' ' << markdown_cell(cell) << " |";
          md << '\n';
          if (r == 0) {
            md << '|';
            for (std::size_t c = 0; c < b.rows[0].size(); ++c) md << "---|";
            md << '\n';
          }
        }
        md << '\n';
        break;
      case Kind::kFigure:
        md << "![" << b.text[1] << "](" << b.text[0] << ")\n\n*" << b.text[1] << "*\n\n";
        break;
    }
  }
  return md.str();
}

std::string ReportDocument::html() const {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" << escape_html(title_)
    << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;line-height:1.45;color:#222}"
       "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}"
       "th{background:#eee}td:first-child,th:first-child{text-align:left}img{max-width:100%}"
       "figcaption{font-style:italic;color:#555}code{background:#f3f3f3;padding:0 3px}</style></head><body>\n";
  h << "<h1>" << escape_html(title_) << "</h1>\n";
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Kind::kHeading:
        h << "<h" << b.level + 1 << '>' << inline_html(b.text[0]) << "</h" << b.level + 1 << ">\n";
        break;
      case Kind::kParagraph:
        h << "<p>" << inline_html(b.text[0]) << "</p>\n";
        break;
      case Kind::kBullets:
        h << "<ul>";
        for (const std::string& item : b.text) h << "<li>" << inline_html(item) << "</li>";
        h << "</ul>\n";
        break;
      case Kind::kTable:
        h << "<table>";
        for (std::size_t r = 0; r < b.rows.size(); ++r) {
          h << "<tr>";
          for (const std::string& cell : b.rows[r])
            h << (r ? "<td>" : "<th>") << inline_html(cell) << (r ? "</td>" : "</th>");
          h << "</tr>";
        }
        h << "</table>\n";
        break;
      case Kind::kFigure:
        h << "<figure><img src=\"" << escape_html(b.text[0]) << "\" alt=\"" << escape_html(b.text[1]) << "\"><figcaption>"
          << inline_html(b.text[1]) << "</figcaption></figure>\n";
        break;
    }
  }
  h << "</body></html>\n";
  return h.str();
}

}  // namespace rpem::analysis
