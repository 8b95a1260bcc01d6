#include "view/view_assets.h"

#include <fstream>
#include <sstream>

#include "common/util/error.h"

namespace cohaptic::view {
namespace {

struct AssetFile {
  const char* url;
  const char* path;  // under its root
  const char* content_type;
  bool library;  // shipped in view/web/lib by deploy/refresh-view-libs.sh
};

constexpr AssetFile kLiveViewFiles[] = {
    {"/", "index.html", "text/html; charset=utf-8", false},
    {"/view.js", "view.js", "text/javascript; charset=utf-8", false},
    {"/style.css", "style.css", "text/css; charset=utf-8", false},
    {"/lib/three.module.min.js", "lib/three.module.min.js", "text/javascript; charset=utf-8", true},
    {"/lib/OrbitControls.js", "lib/OrbitControls.js", "text/javascript; charset=utf-8", true},
    {"/lib/protobuf.min.js", "lib/protobuf.min.js", "text/javascript; charset=utf-8", true},
};

constexpr AssetFile kRatingFiles[] = {
    {"/", "rate.html", "text/html; charset=utf-8", false},
    {"/rate.js", "rate.js", "text/javascript; charset=utf-8", false},
    {"/lib/protobuf.min.js", "lib/protobuf.min.js", "text/javascript; charset=utf-8", true},
};

constexpr AssetFile kProtoFiles[] = {
    {"/proto/cohaptic/view.proto", "cohaptic/view.proto", "text/plain; charset=utf-8", false},
    {"/proto/cohaptic/messages.proto", "cohaptic/messages.proto", "text/plain; charset=utf-8",
     false},
    {"/proto/cohaptic/recording.proto", "cohaptic/recording.proto", "text/plain; charset=utf-8",
     false},
};

std::string read_file(const std::filesystem::path& file, bool library) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    const std::string how =
        library ? " (the view's libraries ship in view/web/lib: restore them from git, or run "
                  "deploy/refresh-view-libs.sh)"
                : "";
    throw Error("view: cannot read " + file.string() + how);
  }
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

}  // namespace

AssetTable load_assets(const std::filesystem::path& web, const std::filesystem::path& proto,
                       ViewPage page) {
  AssetTable table;
  const auto add_web_files = [&](const auto& files) {
    for (const AssetFile& file : files)
      table[file.url] = {file.content_type, read_file(web / file.path, file.library)};
  };
  if (page == ViewPage::live_view)
    add_web_files(kLiveViewFiles);
  else
    add_web_files(kRatingFiles);
  for (const AssetFile& file : kProtoFiles)
    table[file.url] = {file.content_type, read_file(proto / file.path, false)};
  table["/index.html"] = table.at("/");
  return table;
}

const Asset* find_asset(const AssetTable& assets, const std::string& resource) {
  const auto found = assets.find(resource.substr(0, resource.find('?')));
  return found == assets.end() ? nullptr : &found->second;
}

}  // namespace cohaptic::view
