// The files the HTML viewer of `phiq animate` inlines, embedded into the binary when it is built
// (embed_assets.cmake; tools/README.md, "phiq animate", says why three.js is Debian's libjs-three).
#pragma once

#include <string_view>

namespace phiq::tools::assets {

extern const std::string_view kPage;       // viewer/page.html: the page, with {{...}} slots for the rest
extern const std::string_view kCss;        // viewer/viewer.css
extern const std::string_view kViewerJs;   // viewer/viewer.js: data, controls, plots' cursor (both views)
extern const std::string_view kPlanarJs;   // viewer/planar.js: the planar mechanism in SVG
extern const std::string_view kSpatialJs;  // viewer/spatial.js: the spatial mechanism in WebGL
extern const std::string_view kThreeJs;    // three.min.js of libjs-three
extern const std::string_view kOrbitJs;    // examples/js/controls/OrbitControls.js of libjs-three

}  // namespace phiq::tools::assets
