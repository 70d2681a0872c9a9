#pragma once
// PNG figures through gnuplot (pngcairo): data blocks are embedded in the script, so a figure is one
// self-contained .gp file beside its .png (re-runnable by hand: `gnuplot fig.gp`).

#include <string>
#include <vector>

namespace rpem::analysis {

/// One named data block: columns of equal length.
struct DataBlock {
  std::string name;  ///< referenced in the script as $name
  std::vector<std::vector<double>> columns;
};

class GnuplotFigure {
 public:
  /// `png_path`: where the figure goes; the script is written next to it with extension .gp.
  GnuplotFigure(std::string png_path, int width_px, int height_px);

  void add_data(DataBlock block);
  /// Script lines after the terminal/output setup (set …, plot …, multiplot …).
  void add_line(const std::string& line);

  /// Writes the script and runs gnuplot; throws std::runtime_error with gnuplot's message on failure.
  void render() const;

 private:
  std::string png_path_;
  int width_px_, height_px_;
  std::vector<DataBlock> data_;
  std::vector<std::string> lines_;
};

/// Quotes a string for a gnuplot script.
[[nodiscard]] std::string gp_quote(const std::string& s);

}  // namespace rpem::analysis
