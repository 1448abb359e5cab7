#include "cvslam/io/effective_config.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace cvslam {

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

std::string EffectiveConfig::yaml() const {
  YAML::Emitter out;
  out << tree_;
  return std::string(out.c_str()) + "\n";
}

Status EffectiveConfig::write(const std::string& path) const {
  std::ofstream out(path, std::ios::trunc);
  if (!out) return Status::Error("cannot write " + path);
  out << "# The configuration this run used: " << (path_.empty() ? "built-in defaults" : path_)
      << " with the command-line overrides (docs/run_format.md). Give it back with --config.\n"
      << yaml();
  out.close();
  return out ? Status::Ok() : Status::Error(path + ": write failed");
}

}  // namespace cvslam
