#pragma once
// Adaptive SIFT (ASIFT of the thesis, §4.2.4–4.2.5): the energy of the difference-of-Gaussian
// image drives the scale factor k so that low-texture images still give enough features and
// high-texture images are not flooded with them.
//
// What is implemented, and why:
//  1. DoG energy, eq. 4.5, normalised per pixel so that thresholds do not depend on the image
//     size: E(k) = (1/nm) Σ D²(i,j), D = G(kσ0)*I − G(σ0)*I, I in grey levels 0..255.
//  2. Scale-factor adaptation, eq. 4.6, iterated as in Fig. 4.5 / §5.10.2: starting from
//     Lowe's k0 = 2^(1/3), while E(k) < S1 set k ← k² (until σ0·k exceeds σmax = 20); if
//     E(k) > S2 set k ← √k (down to 2^(1/max_octave_layers)).
//  3. The DoG pyramid and keypoint localisation are OpenCV's SIFT with
//     nOctaveLayers = round(1/log2 k) (so its inter-level factor is the adapted k), and its
//     contrast threshold tied to the measured DoG energy: the DoG threshold is
//     contrast_gain·√E(k) grey levels instead of a constant. OpenCV compares the DoG with an
//     absolute threshold and so loses almost every feature when the texture is weak (blur,
//     haze, low contrast); an energy-relative threshold is the thesis's point — "detect a
//     suitable number of features" (§4.2.5) — made explicit.
//  4. Resolution of the first octave: OpenCV (like Lowe) doubles the image before the first
//     octave; that octave is ≈ 3/4 of the pyramid and extremum search and ≈ 75 % of the
//     detector's time. With upsample_first_octave = false the pyramid starts at the input
//     resolution instead (no octave below σ0 at the input's pixel size; features are coarser
//     and fewer at small images, ≈ 2× faster; docs/front_end.md has the figures).
//  5. A band on the count: at most max_features (strongest DoG responses); below
//     min_features the threshold is halved and detection repeated (at most `retries` times),
//     the count-level counterpart of the k ← k² step.
// The thesis's thresholds (E_th = 30, 50, 80 in §4.2.5, §5.10) are in units it does not
// define, so S1 and S2 here are calibrated for the per-pixel energy above (EuRoC V1_01 frames
// have E(k0) ≈ 5; a 2.5-px blurred, 0.3-contrast copy ≈ 0.09).

#include <opencv2/core.hpp>

#include "cvslam/core/status.h"
#include "cvslam/vision/features.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::vision {

struct AdaptiveSiftOptions {
  double sigma0 = 1.6;                ///< σ0, scale of the first level (Lowe)
  double energy_low = 0.5;            ///< S1: E below this → k ← k² (eq. 4.6) [grey²]
  double energy_high = 20.0;          ///< S2: E above this → k ← √k (eq. 4.6) [grey²]
  double sigma_max = 20.0;            ///< σmax: k is not raised beyond σ0·k > σmax (§4.2.5)
  int max_octave_layers = 6;          ///< smallest k = 2^(1/max_octave_layers)
  double contrast_gain = 1.2;         ///< DoG threshold = contrast_gain·√E(k) [grey levels]
  double min_contrast = 0.15;         ///< floor of the DoG threshold [grey levels] (noise)
  double edge_threshold = 10.0;       ///< principal-curvature ratio r (Lowe; Fig. 4.7.b)
  int min_features = 150;             ///< lower end of the band (retry with half the threshold)
  int max_features = 600;             ///< upper end of the band (strongest kept)
  int retries = 2;                    ///< threshold halvings when below min_features
  bool upsample_first_octave = true;  ///< false: the pyramid starts at the input resolution

  Status load(const ConfigNode& node);
};

/// Per-pixel DoG energy, eq. 4.5 (normalised by n·m): G(kσ0)*I − G(σ0)*I, I in 0..255.
double dogEnergy(const cv::Mat& gray, double sigma0, double k);

/// Result of the eq. 4.6 iteration for one image.
struct ScaleFactorChoice {
  double k = 0.0;         ///< adapted scale factor
  double energy = 0.0;    ///< E(k) after adaptation
  double energy0 = 0.0;   ///< E(k0) before adaptation
  int octave_layers = 3;  ///< round(1/log2 k): OpenCV levels per octave
};
ScaleFactorChoice adaptScaleFactor(const cv::Mat& gray, const AdaptiveSiftOptions& options);

/// Detects and describes adaptive SIFT features (CV_8U descriptors, 128 bytes).
Status detectAdaptiveSift(const cv::Mat& gray, const AdaptiveSiftOptions& options, Features* out,
                          ScaleFactorChoice* choice = nullptr);

}  // namespace cvslam::vision
