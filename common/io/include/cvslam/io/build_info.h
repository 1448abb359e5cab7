#pragma once
// The code a program was built from, for the run record (run.json `commit`): `git describe
// --always --dirty` of the source tree at build time (cmake/BuildInfo.cmake), "unknown"
// outside a git checkout.

namespace cvslam {

const char* buildCommit();

}  // namespace cvslam
