#include "cvslam/vision/daubechies.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace cvslam::vision {

namespace {

// Daubechies minimum-phase low-pass filters db1…db10 (Σh = √2, Σh² = 1; orthogonal to their
// even shifts, tests/swif/test_swif_wavelet.cpp).
const std::vector<std::vector<double>> kLowPass = {
    // db1 (2 taps)
    {0.70710678118654757, 0.70710678118654757},
    // db2 (4 taps)
    {0.48296291314453416, 0.83651630373780783, 0.22414386804201342, -0.1294095225512604},
    // db3 (6 taps)
    {0.33267055295008258, 0.80689150931109244, 0.45987750211849165, -0.13501102001025458,
     -0.085441273882026672, 0.035226291885709526},
    // db4 (8 taps)
    {0.2303778133088964, 0.71484657055291556, 0.63088076792985892, -0.027983769416859483,
     -0.18703481171909297, 0.030841381835560646, 0.032883011666885155, -0.010597401785069014},
    // db5 (10 taps)
    {0.16010239797419298, 0.60382926979718987, 0.72430852843777316, 0.13842814590132071,
     -0.24229488706638233, -0.032244869584638479, 0.077571493840045733, -0.0062414902127982726,
     -0.012580751999082001, 0.0033357252854737747},
    // db6 (12 taps)
    {0.1115407433501094, 0.49462389039845273, 0.75113390802109525, 0.31525035170919785,
     -0.22626469396543963, -0.12976686756726163, 0.097501605587322862, 0.027522865530305703,
     -0.031582039317486009, 0.00055384220116149894, 0.0047772575109455064, -0.0010773010853084792},
    // db7 (14 taps)
    {0.07785205408500924, 0.39653931948191756, 0.72913209084623554, 0.46978228740519334,
     -0.1439060039285657, -0.22403618499387476, 0.071309219266830329, 0.080612609151083162,
     -0.038029936935014511, -0.016574541630666885, 0.012550998556099861, 0.00042957797292136554,
     -0.0018016407040474937, 0.00035371379997452067},
    // db8 (16 taps)
    {0.054415842243103967, 0.31287159091429978, 0.67563073629728898, 0.58535468365420684,
     -0.015829105256348678, -0.28401554296154635, 0.00047248457391290197, 0.12874742662047867,
     -0.017369301001807749, -0.04408825393079463, 0.013981027917398258, 0.0087460940474057541,
     -0.0048703529934515611, -0.00039174037337694808, 0.00067544940645056857,
     -0.00011747678412476935},
    // db9 (18 taps)
    {0.038077947363878317, 0.24383467461259012, 0.60482312369011093, 0.65728807805129996,
     0.13319738582500856, -0.29327378327917503, -0.09684078322297543, 0.14854074933810607,
     0.030725681479332991, -0.067632829061329863, 0.00025094711483146731, 0.022361662123679103,
     -0.0047232047577514058, -0.0042815036824634303, 0.0018476468830562274, 0.00023038576352319616,
     -0.00025196318894271023, 3.9347320316271589e-05},
    // db10 (20 taps)
    {0.026670057900555544,   0.18817680007769144,     0.52720118893172541,
     0.68845903945360354,    0.28117234366057714,     -0.24984642432731302,
     -0.1959462743773793,    0.127369340335795,       0.093057364603570045,
     -0.0713941471663955,    -0.029457536821876507,   0.033212674059341231,
     0.0036065535669560834,  -0.010733175483330571,   0.00139535174705291,
     0.001992405295185054,   -0.00068585669495971151, -0.0001164668551292855,
     9.3588670320069578e-05, -1.3264202894521238e-05},
};

// Index of the energy centroid Σ n h[n]² of a filter, rounded: the sample the filter "sits on".
// Daubechies filters are not linear-phase; anchoring at the centroid instead of the middle keeps
// the details of db2 and db10 on the same pixel (they are compared in scale, §4.4.3.2 ii).
double centroid(const cv::Mat& kernel) {
  double m0 = 0.0, m1 = 0.0;
  for (int i = 0; i < kernel.rows; ++i) {
    const double w = kernel.at<float>(i) * kernel.at<float>(i);
    m0 += w;
    m1 += w * i;
  }
  return m1 / m0;
}

struct Bank {
  cv::Mat low, high;  // CV_32F column vectors
  int low_anchor = 0, high_anchor = 0;
  double low_delay = 0.0, high_delay = 0.0;  // centroid − anchor
};

const Bank& bank(int order) {
  static const std::vector<Bank> banks = [] {
    std::vector<Bank> b(kLowPass.size());
    for (std::size_t k = 0; k < kLowPass.size(); ++k) {
      const std::vector<double>& h = kLowPass[k];
      const int n = static_cast<int>(h.size());
      b[k].low.create(n, 1, CV_32F);
      b[k].high.create(n, 1, CV_32F);
      for (int i = 0; i < n; ++i) {
        b[k].low.at<float>(i) = static_cast<float>(h[static_cast<std::size_t>(i)]);
        const double sign = (i % 2 == 0) ? 1.0 : -1.0;
        b[k].high.at<float>(i) = static_cast<float>(sign * h[static_cast<std::size_t>(n - 1 - i)]);
      }
      const double cl = centroid(b[k].low), ch = centroid(b[k].high);
      b[k].low_anchor = static_cast<int>(std::lround(cl));
      b[k].high_anchor = static_cast<int>(std::lround(ch));
      b[k].low_delay = cl - b[k].low_anchor;
      b[k].high_delay = ch - b[k].high_anchor;
    }
    return b;
  }();
  return banks[static_cast<std::size_t>(order - 1)];
}

// Separable filtering: kx along x (anchor ax), ky along y (anchor ay); mirrored borders.
void filter(const cv::Mat& src, const cv::Mat& kx, int ax, const cv::Mat& ky, int ay,
            cv::Mat* dst) {
  cv::sepFilter2D(src, *dst, CV_32F, kx, ky, cv::Point(ax, ay), 0.0, cv::BORDER_REFLECT_101);
}

}  // namespace

const std::vector<double>& daubechiesLowPass(int order) {
  static const std::vector<double> kEmpty;
  if (order < 1 || order > kMaxDaubechiesOrder) return kEmpty;
  return kLowPass[static_cast<std::size_t>(order - 1)];
}

double approximationDelay(int order) {
  return bank(order).low_delay;
}

double detailDelay(int order) {
  const Bank& b = bank(order);
  return 0.5 * (b.low_delay + b.high_delay);
}

void waveletLevel(const cv::Mat& a, int order, bool want_next, WaveletLevel* out) {
  const Bank& b = bank(order);
  filter(a, b.low, b.low_anchor, b.high, b.high_anchor, &out->horizontal);
  filter(a, b.high, b.high_anchor, b.low, b.low_anchor, &out->vertical);
  filter(a, b.high, b.high_anchor, b.high, b.high_anchor, &out->diagonal);
  if (want_next) {
    cv::Mat low;
    filter(a, b.low, b.low_anchor, b.low, b.low_anchor, &low);
    // Decimation by 2 (Figure 4.42): keep the even samples.
    out->next.create((a.rows + 1) / 2, (a.cols + 1) / 2, CV_32F);
    for (int y = 0; y < out->next.rows; ++y) {
      const float* src = low.ptr<float>(2 * y);
      float* dst = out->next.ptr<float>(y);
      for (int x = 0; x < out->next.cols; ++x) dst[x] = src[2 * x];
    }
  }
}

}  // namespace cvslam::vision
