#include "cvslam/io/config_node.h"

#include <fstream>

namespace cvslam {

ConfigNode::ConfigNode(YAML::Node node, std::shared_ptr<Shared> shared, std::string path)
    : node_(std::move(node)), shared_(std::move(shared)), path_(std::move(path)) {
  if (node_ && node_.IsMap()) shared_->sections.emplace(path_, node_);
}

Expected<ConfigNode> ConfigNode::loadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path + ": cannot open config file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return fromString(buffer.str(), path);
}

Expected<ConfigNode> ConfigNode::fromString(const std::string& yaml, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    return Status::Error(source + ": invalid YAML: " + e.what());
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);  // an empty file: all defaults
  if (!root.IsMap()) return Status::Error(source + ": top level must be a map of keys");
  auto shared = std::make_shared<Shared>();
  shared->source = source;
  return ConfigNode(root, shared, "");
}

ConfigNode ConfigNode::empty(const std::string& source) {
  auto shared = std::make_shared<Shared>();
  shared->source = source;
  return ConfigNode(YAML::Node(YAML::NodeType::Map), shared, "");
}

std::string ConfigNode::keyPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

std::string ConfigNode::where(const std::string& key) const {
  return shared_->source + ": " + keyPath(key);
}

void ConfigNode::markRead(const std::string& key) const {
  shared_->read_keys[path_].insert(key);
}

void ConfigNode::recordError(const std::string& key, const std::string& reason) const {
  shared_->errors.push_back(where(key) + ": " + reason);
}

YAML::Node ConfigNode::lookup(const std::string& key) const {
  if (!node_ || !node_.IsMap()) return YAML::Node();
  // Copy so that operator[] on a const node never inserts.
  const YAML::Node& n = node_;
  return n[key];
}

void ConfigNode::recordValue(const std::string& key, std::string text) const {
  std::string path = keyPath(key);
  const auto [it, added] = shared_->value_index.emplace(path, shared_->values.size());
  if (added)
    shared_->values.push_back({std::move(path), std::move(text)});
  else
    shared_->values[it->second].text = std::move(text);
}

std::vector<ConfigNode::Value> ConfigNode::values() const {
  return shared_->values;
}

bool ConfigNode::has(const std::string& key) const {
  YAML::Node n = lookup(key);
  return n && !n.IsNull();
}

std::vector<std::string> ConfigNode::keys() const {
  std::vector<std::string> out;
  if (node_ && node_.IsMap())
    for (const auto& kv : node_) out.push_back(kv.first.as<std::string>());
  return out;
}

ConfigNode ConfigNode::child(const std::string& key) const {
  markRead(key);
  YAML::Node n = lookup(key);
  if (!n || n.IsNull()) return ConfigNode(YAML::Node(YAML::NodeType::Map), shared_, keyPath(key));
  if (!n.IsMap()) {
    recordError(key, "expected a section (a map of keys)");
    return ConfigNode(YAML::Node(YAML::NodeType::Map), shared_, keyPath(key));
  }
  return ConfigNode(n, shared_, keyPath(key));
}

std::string ConfigNode::sectionText(const std::string& key) const {
  markRead(key);
  const YAML::Node n = lookup(key);
  if (!n || n.IsNull()) return "";
  if (!n.IsMap()) {
    recordError(key, "expected a section (a map of keys)");
    return "";
  }
  YAML::Emitter out;
  out << n;
  return out.c_str();
}

std::vector<ConfigNode> ConfigNode::sequence(const std::string& key) const {
  markRead(key);
  std::vector<ConfigNode> out;
  YAML::Node n = lookup(key);
  if (!n || n.IsNull()) return out;
  if (!n.IsSequence()) {
    recordError(key, "expected a list");
    return out;
  }
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string item_path = keyPath(key) + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap()) {
      shared_->errors.push_back(shared_->source + ": " + item_path + ": expected a map of keys");
      continue;
    }
    out.push_back(ConfigNode(n[i], shared_, item_path));
  }
  return out;
}

bool ConfigNode::check(bool condition, const std::string& key, const std::string& reason) const {
  if (!condition) recordError(key, reason);
  return condition;
}

Status ConfigNode::status() const {
  if (shared_->errors.empty()) return Status::Ok();
  return Status::Error(shared_->errors.front());
}

Status ConfigNode::finish() const {
  if (!shared_->errors.empty()) return status();
  for (const auto& [path, section] : shared_->sections) {
    const auto& read = shared_->read_keys[path];
    for (const auto& kv : section) {
      const std::string key = kv.first.as<std::string>();
      if (!read.count(key)) {
        return Status::Error(shared_->source + ": " + (path.empty() ? key : path + "." + key) +
                             ": unknown key");
      }
    }
  }
  return Status::Ok();
}

}  // namespace cvslam
