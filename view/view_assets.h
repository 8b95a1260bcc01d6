// The files a view server's page is made of, as it serves them. The live view: its page
// (view/web: index.html, view.js, style.css) and the two libraries shipped beside it in
// view/web/lib (three.js, protobufjs; no npm and no CDN at run time). The rating page of a
// study rated by people (lab/rating_page.h): rate.html and rate.js, with protobufjs. Both:
// the schema the page decodes (proto/cohaptic/view.proto and the two files it imports).
// Every file is read once, at start, so a missing one is an error before any browser comes.
#pragma once

#include <filesystem>
#include <map>
#include <string>

namespace cohaptic::view {

struct Asset {
  std::string content_type;
  std::string body;
};

enum class ViewPage { live_view, rating };

/// URL path ("/", "/view.js", "/lib/three.module.min.js", ...) -> the file's content.
using AssetTable = std::map<std::string, Asset>;

/// Reads every asset of `page` from `web` (view/web) and `proto` (proto/); the page itself
/// is served at "/". Throws Error naming the first missing file, and for a library how to
/// restore it.
AssetTable load_assets(const std::filesystem::path& web, const std::filesystem::path& proto,
                       ViewPage page = ViewPage::live_view);

/// The asset for a request's path, query string ignored; null when there is none.
const Asset* find_asset(const AssetTable& assets, const std::string& resource);

}  // namespace cohaptic::view
