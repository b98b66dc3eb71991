// A name → value table for every choice made by name (integrators, analyses); an unknown name
// gets an error that lists the registry's own keys, so the message cannot drift from the code.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace pd {

template <class T>
class Registry {
 public:
  explicit Registry(std::string what) : what_(std::move(what)) {}

  Registry& add(const std::string& name, T value) {
    items_.emplace(name, std::move(value));
    return *this;
  }
  bool contains(const std::string& name) const { return items_.count(name) != 0; }

  const T& get(const std::string& name) const {
    auto it = items_.find(name);
    if (it == items_.end()) throw Error(unknown_message(name));
    return it->second;
  }

  std::vector<std::string> keys() const {
    std::vector<std::string> out;
    for (const auto& item : items_) out.push_back(item.first);
    return out;
  }

  // "unknown integrator 'rk4'; known: verlet"
  std::string unknown_message(const std::string& name) const {
    std::string known;
    for (const auto& key : keys()) known += (known.empty() ? "" : ", ") + key;
    return "unknown " + what_ + " '" + name + "'; known: " + known;
  }

 private:
  std::string what_;
  std::map<std::string, T> items_;
};

}  // namespace pd
