#pragma once
/// The strict reader of one JSON object of a scene (core/scene.cpp's parse_scene): every key must be read, types
/// and ranges are checked, and the first problem is kept as an error naming the key's whole path. Internal to the
/// scene parser.

#include <set>
#include <sstream>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/scene_enums.h"
#include "core/scene_json.h"
#include "core/types.h"

namespace palpate::scene_reader {

using Json = nlohmann::json;

inline std::string fmt_num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Reads one JSON object strictly: every key must be read, types and ranges are checked,
// and the first problem is kept as an error naming the full key path.
class ObjectReader {
 public:
  ObjectReader(const Json& j, std::string prefix, std::string* error)
      : j_(j), prefix_(std::move(prefix)), error_(error) {
    // an absent (null) section takes its defaults
    if (error_->empty() && !j_.is_null() && !j_.is_object()) fail(prefix_.empty() ? "top level" : prefix_.substr(0, prefix_.size() - 1), "must be an object");
  }

  bool has(const std::string& key) const { return j_.is_object() && j_.contains(key); }
  bool has_string(const std::string& key) const { return has(key) && j_[key].is_string(); }

  void number(const std::string& key, double* out, double lo, double hi) {
    const Json* v = take(key);
    if (!v) return;
    if (!v->is_number()) return fail(path(key), "must be a number");
    const double x = v->get<double>();
    if (!std::isfinite(x) || x < lo || x > hi)
      return fail(path(key), fmt_num(x) + " out of range [" + fmt_num(lo) + ", " + fmt_num(hi) + "]");
    *out = x;
  }

  void integer(const std::string& key, int* out, int lo, int hi) {
    const Json* v = take(key);
    if (!v) return;
    if (!v->is_number_integer()) return fail(path(key), "must be an integer");
    const std::string range = " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    // 2^63 and beyond arrive unsigned: read as long long they would print (and compare) as negative
    if (v->is_number_unsigned() && v->get<unsigned long long>() > static_cast<unsigned long long>(hi))
      return fail(path(key), std::to_string(v->get<unsigned long long>()) + range);
    const long long x = v->get<long long>();
    if (x < lo || x > hi) return fail(path(key), std::to_string(x) + range);
    *out = static_cast<int>(x);
  }

  void boolean(const std::string& key, bool* out) {
    const Json* v = take(key);
    if (!v) return;
    if (!v->is_boolean()) return fail(path(key), "must be true or false");
    *out = v->get<bool>();
  }

  void string(const std::string& key, std::string* out) {
    const Json* v = take(key);
    if (!v) return;
    if (!v->is_string()) return fail(path(key), "must be a string");
    *out = v->get<std::string>();
  }

  // A string that must be one of an enum's names (core/scene_enums.h); *out untouched when absent or unknown.
  template <typename E>
  void name(const std::string& key, E* out) {
    std::string s;
    const bool present = has(key);
    string(key, &s);
    if (!present || !error_->empty()) return;
    if (const auto v = from_name<E>(s)) {
      *out = *v;
      return;
    }
    fail(path(key), "'" + s + "' is not one of: " + names(E{}).list());
  }

  // A string that must be one of `choices`; returns its position or -1.
  int choice(const std::string& key, const std::vector<std::string>& choices) {
    std::string s;
    const bool present = has(key);
    string(key, &s);
    if (!present || !error_->empty()) return -1;
    for (std::size_t i = 0; i < choices.size(); ++i)
      if (choices[i] == s) return static_cast<int>(i);
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
    fail(path(key), "'" + s + "' is not one of: " + list);
    return -1;
  }

  /// [lo, hi]: two numbers within [min, max], the first not above the second.
  void range(const std::string& key, double* lo_out, double* hi_out, double min, double max) {
    const Json* v = take(key);
    if (!v) return;
    if (!v->is_array() || v->size() != 2 || !(*v)[0].is_number() || !(*v)[1].is_number())
      return fail(path(key), "must be an array of 2 numbers [low, high]");
    const double lo = (*v)[0].get<double>(), hi = (*v)[1].get<double>();
    for (const double x : {lo, hi})
      if (!(x >= min && x <= max)) return fail(path(key), fmt_num(x) + " out of range [" + fmt_num(min) + ", " + fmt_num(max) + "]");
    if (lo > hi) return fail(path(key), "low " + fmt_num(lo) + " is above high " + fmt_num(hi));
    *lo_out = lo;
    *hi_out = hi;
  }
  void vec3(const std::string& key, Vec3* out, double lo, double hi) {
    const Json* v = take(key);
    if (!v) return;
    vec3_value(*v, path(key), out, lo, hi);
  }

  void vec3_value(const Json& v, const std::string& p, Vec3* out, double lo, double hi) {
    if (!v.is_array() || v.size() != 3) return fail(p, "must be an array of 3 numbers");
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number()) return fail(p, "must be an array of 3 numbers");
      const double x = v[i].get<double>();
      if (!std::isfinite(x) || x < lo || x > hi)
        return fail(p + "[" + std::to_string(i) + "]", fmt_num(x) + " out of range [" + fmt_num(lo) + ", " + fmt_num(hi) + "]");
      (*out)[i] = x;
    }
  }

  // The sub-object at key (null json when absent) for a nested reader.
  const Json& object(const std::string& key) {
    const Json* v = take(key);
    return v ? *v : null_;
  }

  const Json* take(const std::string& key) {
    if (!error_->empty() || !j_.is_object() || !j_.contains(key)) return nullptr;
    used_.insert(key);
    return &j_.at(key);
  }

  void require(const std::string& key) {
    if (error_->empty() && !has(key)) fail(path(key), "is required");
  }

  // Reports the first key that nobody read.
  void finish() {
    if (!error_->empty() || !j_.is_object()) return;
    for (const auto& [k, v] : j_.items())
      if (!used_.count(k)) return fail(path(k), "unknown key");
  }

  std::string path(const std::string& key) const { return prefix_ + key; }

  void fail(const std::string& p, const std::string& msg) {
    if (error_->empty()) *error_ = p + ": " + msg;
  }

 private:
  const Json& j_;
  std::string prefix_;
  std::string* error_;
  std::set<std::string> used_;
  Json null_;
};

}  // namespace palpate::scene_reader
