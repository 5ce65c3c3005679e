#pragma once
/// What a frame says besides the model: the displacement colour map, and text and a legend drawn into the RGBA image
/// after it is read back (a 5 x 7 bitmap font of its own, scaled with the image). Plain functions over an image;
/// nothing allocated per call but the strings handed in.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace palpate {

/// An RGBA image being annotated: w x h pixels, 4 bytes each, top row first.
struct RgbaImage {
  uint8_t* px = nullptr;
  int w = 0, h = 0;
};

using Rgba8 = std::array<uint8_t, 4>;

/// The displacement colour map at u in [0, 1] (clamped; NaN counts as 0): the model's own blue-grey at 0 (an
/// untouched surface looks as it does uncoloured), through yellow and orange to dark red at 1.
Rgba8 displacement_color(double u);
/// The colour of faces a cut made (the cut's walls): a tissue red, apart from every colour of the map.
inline constexpr Rgba8 kCutFaceColor{178, 40, 96, 255};

/// The smallest of 1, 2 and 5 times a power of ten that is at least x (x > 0; 0 for anything else).
double nice_ceil(double x);
/// A length to two significant figures in the unit that reads best: "0", "250 um", "1.5 mm", "12 mm", "1.2 m".
std::string format_length(double m);
/// A fraction as a percentage to two significant figures: "0", "0.5 %", "20 %", "150 %".
std::string format_percent(double fraction);
/// A force to two significant figures: "0.42 N", "3.3 N", "12 N".
std::string format_force(double n);

/// Text scale for an image of height h: one more per 240 rows (2 at 480, 4 at 1080), at least 1.
int text_scale(int h);
/// Width and height in pixels of `text` at `scale` (7 rows, 5 columns and a column's gap per glyph).
std::array<int, 2> text_size(std::string_view text, int scale);
/// Draws `text` with its top-left at (x, y), clipped to the image; characters the font lacks are blanks.
void draw_text(RgbaImage img, int x, int y, std::string_view text, int scale, Rgba8 color);
/// Fills [x0, x1) x [y0, y1), clipped; alpha blends over the image (255: replaces).
void fill_rect(RgbaImage img, int x0, int y0, int x1, int y1, Rgba8 color);

/// A corner of the image an inset is drawn in.
enum class Corner { kTopRight, kTopLeft, kBottomLeft, kBottomRight };
/// The box {x0, y0, x1, y1} of an inset of outer size w x h in `corner` of an img_w x img_h image, pad pixels in.
std::array<int, 4> corner_box(int img_w, int img_h, int w, int h, int pad, Corner corner);

/// The force trace (in the bottom-left corner unless told): values (oldest first, one a frame; `capacity` of them
/// span span_s seconds, the full width) from 0 to scale_N, a line on a light ground with its scale and span written.
/// Returns the box it drew in ({x0, y0, x1, y1}); with draw false, only the box it would draw in.
std::array<int, 4> draw_force_trace(RgbaImage img, const float* values, std::size_t n, std::size_t capacity,
                                    double scale_N, double span_s, Corner corner = Corner::kBottomLeft,
                                    bool draw = true);

/// The legend (in the image's top-right corner unless told): the title of what the colours show and a vertical bar of the colour
/// map from 0 (bottom) to `top` (its label: the range, in its unit) when the title is not empty, and (when cut_faces)
/// a swatch for the cut's faces; `force_ref_N` > 0 adds the force arrow's scale: a bar force_ref_px long labelled with
/// that force. Returns the box it drew in ({x0, y0, x1, y1}); with draw false, only the box it would draw in.
std::array<int, 4> draw_legend(RgbaImage img, const std::string& title, const std::string& top, bool cut_faces,
                               double force_ref_N, double force_ref_px, Corner corner = Corner::kTopRight,
                               bool draw = true);

}  // namespace palpate
