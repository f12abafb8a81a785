// Shared model builders for the Google Benchmark programs.
#pragma once

#include "dynid/mesh/generators.hpp"

namespace dynid::bench {

inline Material Steel() { return {"steel", 2.1e11, 0, 0.3, 7850}; }
// Strong axis = local y (columns: local z along global X; beams: local y horizontal), see frame3d_axes.
inline Section Column() { return {"HEB300", 1.49e-2, 2.52e-4, 8.56e-5, 1.85e-6}; }
inline Section Beam() { return {"IPE400", 8.45e-3, 2.31e-4, 1.32e-5, 5.1e-7}; }

/// A square 2D frame (n x n bays and stories, members split in `div`).
inline Model Frame2D(int n, int div) {
  Frame2DSpec f;
  f.bays = f.stories = n;
  f.divisions = div;
  f.span = 6;
  f.height = 3.5;
  f.material = Steel();
  f.column = Column();
  f.beam = Beam();
  return make_frame2d(f);
}

/// A cubic 3D frame (n x n x n bays and stories, members split in `div`).
inline Model Frame3D(int n, int div) {
  Frame3DSpec f;
  f.bays_x = f.bays_y = f.stories = n;
  f.divisions = div;
  f.span_x = f.span_y = 6;
  f.height = 3.5;
  f.material = Steel();
  f.column = Column();
  f.beam = Beam();
  return make_frame3d(f);
}

}  // namespace dynid::bench
