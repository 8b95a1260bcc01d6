// The files the view's page is made of, as the view server serves them: its own page
// (view/web: index.html, view.js, style.css), the libraries npm installed beside it from
// view/web/package-lock.json (three.js, protobufjs; no CDN at run time), and the schema the
// page decodes (proto/cohaptic/view.proto and the two files it imports). Every file is
// read once, at start, so a missing one is an error before any browser comes.
#pragma once

#include <filesystem>
#include <map>
#include <string>

namespace cohaptic::view {

struct Asset {
  std::string content_type;
  std::string body;
};

/// URL path ("/", "/view.js", "/lib/three.module.js", ...) -> the file's content.
using AssetTable = std::map<std::string, Asset>;

/// Reads every asset from `web` (view/web) and `proto` (proto/). Throws Error naming the
/// first missing file, and for a library the command that installs it.
AssetTable load_assets(const std::filesystem::path& web, const std::filesystem::path& proto);

/// The asset for a request's path, query string ignored; null when there is none.
const Asset* find_asset(const AssetTable& assets, const std::string& resource);

}  // namespace cohaptic::view
