#pragma once
// Every options struct prints itself and compares equal through its own loader (config_node.h):
// loading a copy from an empty configuration changes nothing and records each key the loader
// reads with the value it holds, so the printout lists exactly the keys the struct reads (a new
// option appears without anyone writing a printer), and two structs are equal when all of
// them are. The printout is YAML that --config reads back.
//
//   std::fputs(describeOptions(config.slam).c_str(), stderr);
//   if (!sameOptions(a, b)) ...

#include <string>
#include <vector>

#include "cvslam/io/config_node.h"

namespace cvslam {

/// Every key `options.load` reads, with its value in `options` (file order of the loader).
template <typename Options>
std::vector<ConfigNode::Value> optionValues(const Options& options) {
  Options copy = options;
  const ConfigNode empty = ConfigNode::empty();
  (void)copy.load(empty);  // an empty file changes nothing; its checks do not matter here
  return empty.values();
}

/// `values` of a struct loaded from the section `section` of a file, named from the file's top.
std::vector<ConfigNode::Value> inSection(std::vector<ConfigNode::Value> values,
                                         const std::string& section);

/// The values as nested YAML ("a.b.key" → a: {b: {key: …}}, block style).
std::string formatOptionValues(const std::vector<ConfigNode::Value>& values);

template <typename Options>
std::string describeOptions(const Options& options) {
  return formatOptionValues(optionValues(options));
}

/// Same keys, same values (doubles compared by their shortest round-trip text, i.e. exactly).
template <typename Options>
bool sameOptions(const Options& a, const Options& b) {
  const std::vector<ConfigNode::Value> va = optionValues(a), vb = optionValues(b);
  if (va.size() != vb.size()) return false;
  for (std::size_t i = 0; i < va.size(); ++i)
    if (va[i].path != vb[i].path || va[i].text != vb[i].text) return false;
  return true;
}

}  // namespace cvslam
