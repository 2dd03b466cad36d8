#include "core/errormap/deviation_color.h"

#include <cmath>

#include "core/types/round_half_away.h"

namespace surfinspect {
namespace {

// Each piece of the colour scale blends two colours, each channel rounded
// from x + (y - x) w, halves away from zero; the constant pieces (beyond the
// scale) blend a colour with itself at weight 0. DeviationColor picks the
// piece and the weight by index: on a part's deviations the sign and the
// band go either way at random, and branches on them are mispredicted. A
// piece holds x and y - x per channel as doubles (exact: small integers).
struct Piece {
  double from[3], step[3];
  constexpr Piece(Rgb a, Rgb b)
      : from{double(a.r), double(a.g), double(a.b)},
        step{double(b.r) - a.r, double(b.g) - a.g, double(b.b) - a.b} {}
};
constexpr Piece kPieces[8] = {
    {{40, 190, 90}, {150, 215, 60}},  // in the band, t >= 0: to warm green
    {{40, 190, 90}, {40, 190, 170}},  // in the band, t < 0: to cool green
    {{255, 235, 0}, {255, 140, 0}},   // above, first half of the ramp
    {{255, 140, 0}, {215, 0, 0}},     // above, second half
    {{0, 230, 230}, {0, 120, 255}},   // below, first half
    {{0, 120, 255}, {0, 0, 190}},     // below, second half
    {{120, 0, 50}, {120, 0, 50}},     // above, beyond the scale
    {{50, 0, 120}, {50, 0, 120}},     // below, beyond the scale
};

}  // namespace

// In the band: t = d / tol, from the mid green towards the warm (t >= 0) or
// the cool green, by |t|. Outside: s = (|d| - tol) / (range - tol), the
// yellow-orange-red ramp above or the cyan-blue ramp below, each in two
// halves (weights 2s and 2s - 1); beyond s = 1, a darker constant colour.
Rgb DeviationColor(double d, double tol, double range) {
  if (std::isnan(d)) return kUnmatchedGrey;
  const double ad = std::abs(d);
  const double t = tol > 0 ? d / tol : 0.0;
  const double s = range > tol ? (ad - tol) / (range - tol) : 1.0;
  const int band = ad <= tol, beyond = s > 1, second_half = !(s < 0.5), below = !(d > 0);
  const int ramp = beyond ? 6 + below : 2 + 2 * below + second_half;
  const Piece& piece = kPieces[band ? int{t < 0} : ramp];
  // Selected by index, not by a conditional: the compiler branches on those.
  const double ramp_weights[3] = {2 * s, 2 * s - 1, 0.0};
  const double weights[2] = {ramp_weights[beyond ? 2 : second_half], std::abs(t)};
  const double w = weights[band];
  auto mix = [&](int c) {
    return static_cast<uint8_t>(RoundHalfAwayFromZero(piece.from[c] + piece.step[c] * w));
  };
  return {mix(0), mix(1), mix(2)};
}

}  // namespace surfinspect
