#pragma once
// The page cvslam_view serves (view/web/index.html, embedded at build time by embed_page.cmake).
#include <string>

namespace cvslam::view {
extern const std::string kViewPage;
}  // namespace cvslam::view
