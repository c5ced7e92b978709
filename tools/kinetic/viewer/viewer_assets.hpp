#pragma once
// The replay page of `kinetic view` (tools/kinetic/viewer/viewer.html and viewer.js, compiled in
// as text): the page has the markers /*KINETIC_TRACE*/ (the trace's lines) and
// /*KINETIC_VIEWER_JS*/ (the script).

namespace kinetic::cli {

extern const char* const kViewerHtml;
extern const char* const kViewerJs;

}  // namespace kinetic::cli
