// Reading and writing plain structs as JSON objects with one list of their
// fields. A struct's fields are named once, in a visit function template
//
//   template <typename V, typename R>  // R: the struct, const when written
//   void VisitBand(V& v, R& band) {
//     v("lower", band.lower_mm);
//     v("upper", band.upper_mm);
//   }
//
// that JsonWriter turns into an object, JsonReader fills from one, and
// JsonLister lists as (key, value) pairs in visiting order. Nested objects
// and lists go through Object and List; Derived values are written and never
// read; Require names a field a reader must find. The reader keeps a field's
// default when it is absent, reads null as NaN, and remembers the first field
// of the wrong type with its path (absl DataLoss: "report.tolerance.within:
// not a count").
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace surfinspect {

// JSON has no NaN: a missing number is null in the object itself, not only
// once dumped, so a serialisation of the object sees the same thing.
inline nlohmann::json JsonNumber(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

// One field with its key, as JsonLister lists it.
struct JsonField {
  std::string key;
  nlohmann::json value;  // null for NaN
};

// Writes the visited fields into a JSON object.
class JsonWriter {
 public:
  static constexpr bool kReads = false;
  nlohmann::json out = nlohmann::json::object();
  void operator()(const char* key, double v) { out[key] = JsonNumber(v); }
  void operator()(const char* key, const std::optional<double>& v) {
    if (v) out[key] = JsonNumber(*v);
  }
  // A vector that does not exist (NaN) is null, like a number.
  void operator()(const char* key, const Eigen::Vector3d& v) {
    out[key] = v.allFinite() ? nlohmann::json{v.x(), v.y(), v.z()} : nlohmann::json(nullptr);
  }
  template <typename T>
  void operator()(const char* key, const T& v) {
    out[key] = v;
  }
  void Require(const char*) {}
  void Derived(const char* key, nlohmann::json v) { out[key] = std::move(v); }
  template <typename S, typename F>
  void Object(const char* key, const S& s, F visit) {
    JsonWriter w;
    visit(w, s);
    out[key] = std::move(w.out);
  }
  template <typename S, typename F>
  void Object(const char* key, const std::optional<S>& s, F visit) {
    if (s) Object(key, *s, visit);
  }
  template <typename S, typename F>
  void List(const char* key, const std::vector<S>& list, F visit) {
    nlohmann::json items = nlohmann::json::array();
    for (const S& s : list) {
      JsonWriter w;
      visit(w, s);
      items.push_back(std::move(w.out));
    }
    out[key] = std::move(items);
  }
};

// Lists the visited fields in visiting order (derived ones left out).
class JsonLister : public JsonWriter {
 public:
  std::vector<JsonField> fields;
  template <typename T>
  void operator()(const char* key, const T& v) {
    JsonWriter w;
    w(key, v);
    fields.push_back({key, w.out[key]});
  }
  void Derived(const char*, const nlohmann::json&) {}
};

// Reads the visited fields from a JSON object, which must outlive the reader. An absent field keeps
// its default and null is NaN; the first field of the wrong type, or a required one missing, is
// remembered with its path (DataLoss).
class JsonReader {
 public:
  static constexpr bool kReads = true;
  JsonReader(const nlohmann::json& j, std::string where) : j_(j), where_(std::move(where)) {
    if (!j_.is_object()) Fail("", "not an object");
  }
  absl::Status status() const { return status_; }

  void operator()(const char* key, double& v) {
    if (const nlohmann::json* x = Get(key))
      Take(key, x->is_number() || x->is_null(), "a number",
           [&] { v = x->is_null() ? NAN : x->get<double>(); });
  }
  void operator()(const char* key, std::optional<double>& v) {
    if (!Get(key)) return;
    v.emplace(NAN);
    (*this)(key, *v);
  }
  void operator()(const char* key, std::size_t& v) {
    if (const nlohmann::json* x = Get(key))
      Take(key, IsCount(*x), "a count", [&] { v = x->get<size_t>(); });
  }
  void operator()(const char* key, int& v) {
    if (const nlohmann::json* x = Get(key))
      Take(key, x->is_number_integer(), "an integer", [&] { v = x->get<int>(); });
  }
  void operator()(const char* key, bool& v) {
    if (const nlohmann::json* x = Get(key))
      Take(key, x->is_boolean(), "true/false", [&] { v = x->get<bool>(); });
  }
  void operator()(const char* key, std::string& v) {
    if (const nlohmann::json* x = Get(key))
      Take(key, x->is_string(), "a string", [&] { v = x->get<std::string>(); });
  }
  void operator()(const char* key, std::vector<std::size_t>& v) {
    const nlohmann::json* x = Get(key);
    if (!x) return;
    const bool ok = x->is_array() && std::all_of(x->begin(), x->end(), IsCount);
    Take(key, ok, "a list of counts", [&] { v = x->get<std::vector<std::size_t>>(); });
  }
  void operator()(const char* key, std::vector<double>& v) {
    const nlohmann::json* x = Get(key);
    if (!x) return;
    const bool ok = x->is_array() && std::all_of(x->begin(), x->end(), [](const nlohmann::json& c) {
                      return c.is_number() || c.is_null();
                    });
    Take(key, ok, "a list of numbers", [&] {
      v.clear();
      for (const nlohmann::json& c : *x) v.push_back(c.is_null() ? NAN : c.get<double>());
    });
  }
  void operator()(const char* key, std::vector<std::string>& v) {
    const nlohmann::json* x = Get(key);
    if (!x) return;
    const bool ok = x->is_array() && std::all_of(x->begin(), x->end(), [](const nlohmann::json& c) {
                      return c.is_string();
                    });
    Take(key, ok, "a list of strings", [&] { v = x->get<std::vector<std::string>>(); });
  }
  void operator()(const char* key, Eigen::Vector3d& v) {
    const nlohmann::json* x = Get(key);
    if (!x) return;
    if (x->is_null()) {
      v = Eigen::Vector3d::Constant(NAN);
      return;
    }
    const bool ok =
        x->is_array() && x->size() == 3 &&
        std::all_of(x->begin(), x->end(), [](const nlohmann::json& c) { return c.is_number(); });
    Take(key, ok, "three numbers", [&] {
      v = {(*x)[0].get<double>(), (*x)[1].get<double>(), (*x)[2].get<double>()};
    });
  }
  void Require(const char* key) {
    if (!Get(key)) Fail(key, "missing");
  }
  void Derived(const char*, const nlohmann::json&) {}
  template <typename S, typename F>
  void Object(const char* key, S& s, F visit) {
    if (const nlohmann::json* x = Get(key)) Nested(*x, absl::StrCat(where_, ".", key), s, visit);
  }
  template <typename S, typename F>
  void Object(const char* key, std::optional<S>& s, F visit) {
    if (Get(key)) Object(key, s.emplace(), visit);
  }
  template <typename S, typename F>
  void List(const char* key, std::vector<S>& list, F visit) {
    const nlohmann::json* x = Get(key);
    if (!x) return;
    if (!x->is_array()) return Fail(key, "not an array");
    for (std::size_t k = 0; k < x->size(); ++k)
      Nested((*x)[k], absl::StrCat(where_, ".", key, "[", k, "]"), list.emplace_back(), visit);
  }

 private:
  static bool IsCount(const nlohmann::json& x) {
    return x.is_number_unsigned() || (x.is_number_integer() && x.get<int64_t>() >= 0);
  }
  const nlohmann::json* Get(const char* key) const {
    return j_.is_object() && j_.contains(key) ? &j_.at(key) : nullptr;
  }
  template <typename F>
  void Take(const char* key, bool ok, const char* kind, F take) {
    if (ok)
      take();
    else
      Fail(key, absl::StrCat("not ", kind));
  }
  template <typename S, typename F>
  void Nested(const nlohmann::json& x, std::string where, S& s, F visit) {
    JsonReader r(x, std::move(where));
    visit(r, s);
    if (status_.ok()) status_ = r.status();
  }
  void Fail(const std::string& key, const std::string& what) {
    if (status_.ok())
      status_ = absl::DataLossError(absl::StrCat(where_, key.empty() ? "" : ".", key, ": ", what));
  }
  const nlohmann::json& j_;
  std::string where_;
  absl::Status status_;
};

}  // namespace surfinspect
