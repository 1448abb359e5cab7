#include "cvslam/io/options_description.h"

#include <yaml-cpp/yaml.h>

namespace cvslam {
namespace {

/// Splits "a.list[2].key" into {"a", "list[2]", "key"}.
std::vector<std::string> segments(const std::string& path) {
  std::vector<std::string> out(1);
  for (char c : path) {
    if (c == '.')
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

}  // namespace

std::vector<ConfigNode::Value> inSection(std::vector<ConfigNode::Value> values,
                                         const std::string& section) {
  for (ConfigNode::Value& v : values) v.path = section + "." + v.path;
  return values;
}

std::string formatOptionValues(const std::vector<ConfigNode::Value>& values) {
  YAML::Node root(YAML::NodeType::Map);
  for (const ConfigNode::Value& v : values) {
    const std::vector<std::string> segs = segments(v.path);
    YAML::Node at = root;
    for (std::size_t i = 0; i + 1 < segs.size(); ++i) {
      const std::string& seg = segs[i];
      const std::size_t bracket = seg.find('[');
      if (bracket == std::string::npos) {
        if (!at[seg] || !at[seg].IsMap()) at[seg] = YAML::Node(YAML::NodeType::Map);
        at.reset(at[seg]);  // reset: re-points `at`; operator= would assign through it
        continue;
      }
      const std::string name = seg.substr(0, bracket);
      const std::size_t index = std::stoul(seg.substr(bracket + 1));
      if (!at[name] || !at[name].IsSequence()) at[name] = YAML::Node(YAML::NodeType::Sequence);
      YAML::Node list = at[name];
      while (list.size() <= index) list.push_back(YAML::Node(YAML::NodeType::Map));
      at.reset(list[index]);
    }
    at[segs.back()] = YAML::Load(v.text);
  }
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

}  // namespace cvslam
