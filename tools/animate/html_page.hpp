// `phiq animate SCENE RESULT -o OUT.html`: one self-contained page that plays the motion (html_motion.*) in the
// planar view (SVG over `phiq plot`'s axes and ground) or the spatial one (WebGL, three.js), beside `phiq plot`'s
// panels of chosen columns against t with a cursor at the time shown; every script, style and datum inlined.
#pragma once

#include <string>
#include <vector>

#include "phiq/clearance.hpp"
#include "phiq/csv_compare.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

// The page for `table`, the result of `scene` read from `result`; `columns` as `phiq plot --columns` (empty: its
// defaults); `clearance`, the scene's `output.clearance` measured (html_clearance.hpp), or null. `row_labels` (one
// per row of `table`, or empty): the rows are separate poses, not a motion (`phiq animate --modes`: one per assembly
// mode, t its number): the viewer shows the label of the nearest row instead of interpolating. `forces` > 0: the
// efforts and reactions drawn as arrows, that many metres per newton (force_arrows.hpp). Throws phiq::Error with one
// line for bad input (see viewer_motion(), plotted_columns(), force_arrows()).
std::string motion_html(const Scene& scene, const CsvTable& table, const std::string& result,
                        const std::vector<std::string>& columns, const ClearanceReport* clearance = nullptr,
                        const std::vector<std::string>& row_labels = {}, double forces = 0.0);

}  // namespace phiq::tools
