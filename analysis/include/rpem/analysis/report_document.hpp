#pragma once
// A report as a list of blocks (headings, paragraphs, tables, figures), written once and rendered as
// Markdown and as a self-contained HTML page (figures referenced by relative path).

#include <string>
#include <vector>

namespace rpem::analysis {

class ReportDocument {
 public:
  explicit ReportDocument(std::string title) : title_(std::move(title)) {}

  void heading(int level, const std::string& text);
  /// Text with Markdown's inline `code` and **bold**, which the HTML rendering converts too.
  void paragraph(const std::string& text);
  void bullets(const std::vector<std::string>& items);
  void table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);
  void figure(const std::string& relative_path, const std::string& caption);

  [[nodiscard]] std::string markdown() const;
  [[nodiscard]] std::string html() const;

 private:
  enum class Kind { kHeading, kParagraph, kBullets, kTable, kFigure };
  struct Block {
    Kind kind;
    int level = 0;
    std::vector<std::string> text;               ///< paragraph / bullets / figure path + caption
    std::vector<std::vector<std::string>> rows;  ///< table, first row the header
  };
  std::string title_;
  std::vector<Block> blocks_;
};

}  // namespace rpem::analysis
