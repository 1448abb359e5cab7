#include "cvslam/io/effective_config.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace cvslam {
namespace {

/// Adds to `into` every key of `base` it does not have; maps present in both merge key by key.
void underlay(YAML::Node into, const YAML::Node& base) {
  for (const auto& entry : base) {
    const std::string key = entry.first.as<std::string>();
    const YAML::Node& view = into;  // a const look-up adds no key
    const YAML::Node mine = view[key];
    if (!mine || mine.IsNull()) {
      into[key] = YAML::Clone(entry.second);
    } else if (mine.IsMap() && entry.second.IsMap()) {
      underlay(into[key], entry.second);
    }
  }
}

std::string joined(const std::vector<std::string>& names, const std::string& separator) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : separator) + n;
  return out;
}

/// The profiles (NAME of NAME.yaml) in `dirs`, sorted, for the message of an unknown one.
std::vector<std::string> profilesIn(const std::vector<std::string>& dirs) {
  std::vector<std::string> names;
  for (const std::string& dir : dirs) {
    std::error_code ec;
    for (const auto& f : std::filesystem::directory_iterator(dir, ec))
      if (f.path().extension() == ".yaml") names.push_back(f.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

}  // namespace

Expected<EffectiveConfig> EffectiveConfig::load(const std::string& path) {
  if (path.empty()) {
    return EffectiveConfig(ConfigNode::empty(), YAML::Node(YAML::NodeType::Map), "");
  }
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open config file");
  std::stringstream text;
  text << in.rdbuf();
  return fromText(text.str(), path);
}

Expected<EffectiveConfig> EffectiveConfig::fromText(const std::string& yaml,
                                                    const std::string& source) {
  Expected<ConfigNode> node = ConfigNode::fromString(yaml, source);
  if (!node.ok()) return node.status();
  // The same text parsed again as the tree the overrides are recorded in (it parsed above).
  YAML::Node tree = YAML::Load(yaml);
  if (tree.IsNull()) tree = YAML::Node(YAML::NodeType::Map);
  return EffectiveConfig(std::move(*node), std::move(tree), source);
}

std::string EffectiveConfig::dir() const {
  if (path_.empty()) return ".";
  const std::filesystem::path parent = std::filesystem::path(path_).parent_path();
  return parent.empty() ? "." : parent.string();
}

void EffectiveConfig::set(const std::vector<std::string>& section, const std::string& key,
                          const std::string& value) {
  // reset() rebinds a yaml-cpp handle; operator= would overwrite the node's content.
  YAML::Node at = tree_;
  for (const std::string& name : section) {
    YAML::Node next = at[name];
    if (!next.IsMap()) next = YAML::Node(YAML::NodeType::Map);
    at.reset(next);
  }
  at[key] = value;
}

Status EffectiveConfig::assign(const std::vector<std::string>& assignments,
                               const std::string& option) {
  if (assignments.empty()) return Status::Ok();
  for (const std::string& a : assignments) {
    const std::size_t eq = a.find('=');
    std::vector<std::string> path;
    for (std::size_t begin = 0; eq != std::string::npos && begin <= eq;) {
      const std::size_t dot = std::min(a.find('.', begin), eq);
      path.push_back(a.substr(begin, dot - begin));
      begin = dot + 1;
    }
    const bool named =
        path.size() >= 2 &&
        std::none_of(path.begin(), path.end(), [](const std::string& p) { return p.empty(); });
    if (!named || eq + 1 == a.size()) {
      return Status::Error(option + ": expected SECTION.KEY=VALUE, e.g. map.kind=full (got '" + a +
                           "')");
    }
    const std::string key = path.back();
    path.pop_back();
    set(path, key, a.substr(eq + 1));
  }
  Expected<ConfigNode> node =
      ConfigNode::fromString(yaml(), (path_.empty() ? "defaults" : path_) + " with " + option);
  if (!node.ok()) return node.status();
  node_ = std::move(*node);
  return Status::Ok();
}

Status EffectiveConfig::applyProfiles(const std::vector<std::string>& dirs) {
  const std::string source = path_.empty() ? "defaults" : path_;
  // Read through a const handle: yaml-cpp's non-const operator[] adds the key it looks up.
  const YAML::Node& tree = tree_;
  while (tree.IsMap() && tree["profile"]) {
    const YAML::Node named = tree["profile"];
    if (!named.IsScalar() || named.Scalar().empty())
      return Status::Error(source + ": profile: must be a profile's name");
    const std::string name = named.Scalar();
    tree_.remove("profile");
    if (std::find(profiles_.begin(), profiles_.end(), name) != profiles_.end())
      return Status::Error(source + ": profile: '" + name + "' names itself through " +
                           joined(profiles_, " < "));
    std::string file;
    for (const std::string& dir : dirs) {
      const std::string candidate = (std::filesystem::path(dir) / (name + ".yaml")).string();
      if (std::filesystem::is_regular_file(candidate)) {
        file = candidate;
        break;
      }
    }
    if (file.empty()) {
      const std::vector<std::string> known = profilesIn(dirs);
      return Status::Error(source + ": profile: unknown profile '" + name + "' (" +
                           (known.empty() ? "no profiles in " + joined(dirs, ", ")
                                          : "one of " + joined(known, ", ")) +
                           ")");
    }
    YAML::Node base;
    try {
      base = YAML::LoadFile(file);
    } catch (const YAML::Exception& e) {
      return Status::Error(file + ": " + e.what());
    }
    if (!base.IsNull() && !base.IsMap()) return Status::Error(file + ": not a YAML map");
    profiles_.push_back(name);
    if (base.IsMap()) underlay(tree_, base);
  }
  if (profiles_.empty()) return Status::Ok();
  // Named as before (the file, "with --set"), and by its profiles.
  Expected<ConfigNode> node = ConfigNode::fromString(
      yaml(), node_.source() + " (profile " + joined(profiles_, " < ") + ")");
  if (!node.ok()) return node.status();
  node_ = std::move(*node);
  return Status::Ok();
}

std::string EffectiveConfig::yaml() const {
  YAML::Emitter out;
  out << tree_;
  return std::string(out.c_str()) + "\n";
}

Status EffectiveConfig::write(const std::string& path) const {
  std::ofstream out(path, std::ios::trunc);
  if (!out) return Status::Error("cannot write " + path);
  out << "# The configuration this run used: " << (path_.empty() ? "built-in defaults" : path_)
      << (profiles_.empty() ? "" : " (profile " + joined(profiles_, " < ") + ", written out)")
      << " with the command-line overrides (docs/run_format.md). Give it back with --config.\n"
      << yaml();
  out.close();
  return out ? Status::Ok() : Status::Error(path + ": write failed");
}

}  // namespace cvslam
