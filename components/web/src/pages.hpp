/// The web component's pages, embedded in the plugin at build time (components/web/pages/):
/// nothing to install beside the plugin, nothing fetched from elsewhere.
#pragma once

namespace dyad::web {
extern const char* const kIndexHtml;         // "/"
extern const char* const kSubjectHtml;       // "/subject"
extern const char* const kExperimenterHtml;  // "/experimenter"
}  // namespace dyad::web
