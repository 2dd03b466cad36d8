// core/types/json_fields.h: one visit function writes, reads and lists a
// struct; the reader keeps defaults, reads null as NaN and names the first
// bad field with its path.
#include "core/types/json_fields.h"

#include <gtest/gtest.h>

namespace surfinspect {
namespace {

struct Inner {
  double x_mm = NAN;
};

struct Outer {
  std::string name;
  std::size_t count = 0;
  int level = 0;
  bool on = false;
  std::optional<double> maybe;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
  std::vector<std::size_t> counts;
  Inner inner;
  std::vector<Inner> items;
};

template <typename V, typename R>
void VisitInner(V& v, R& i) {
  v("x_mm", i.x_mm);
}

template <typename V, typename R>
void VisitOuter(V& v, R& o) {
  v.Require("name");
  v("name", o.name);
  v("count", o.count);
  v("level", o.level);
  v("on", o.on);
  v("maybe", o.maybe);
  v("at", o.at);
  v("counts", o.counts);
  v.Derived("twice", 2 * o.count);
  v.Object("inner", o.inner, [](auto& w, auto& i) { VisitInner(w, i); });
  v.List("items", o.items, [](auto& w, auto& i) { VisitInner(w, i); });
}

Outer Sample() {
  Outer o;
  o.name = "a\"b";
  o.count = 7;
  o.level = -3;
  o.on = true;
  o.maybe = 0.25;
  o.at = {1.5, -2, 3};
  o.counts = {1, 2, 3};
  o.inner.x_mm = NAN;
  o.items = {{0.5}, {NAN}};
  return o;
}

TEST(JsonFields, WriteThenReadGivesTheSameFieldsAndNullForNaN) {
  JsonWriter w;
  VisitOuter(w, static_cast<const Outer&>(Sample()));
  EXPECT_TRUE(w.out["inner"]["x_mm"].is_null());
  EXPECT_EQ(w.out["twice"], 14);
  Outer back;
  JsonReader r(w.out, "outer");
  VisitOuter(r, back);
  ASSERT_TRUE(r.status().ok()) << r.status();
  EXPECT_EQ(back.name, "a\"b");
  EXPECT_EQ(back.count, 7u);
  EXPECT_EQ(back.level, -3);
  EXPECT_TRUE(back.on);
  EXPECT_EQ(back.maybe.value_or(0), 0.25);
  EXPECT_EQ(back.at, Eigen::Vector3d(1.5, -2, 3));
  EXPECT_EQ(back.counts, (std::vector<std::size_t>{1, 2, 3}));
  EXPECT_TRUE(std::isnan(back.inner.x_mm));
  ASSERT_EQ(back.items.size(), 2u);
  EXPECT_EQ(back.items[0].x_mm, 0.5);
  EXPECT_TRUE(std::isnan(back.items[1].x_mm));
  JsonWriter again;
  VisitOuter(again, static_cast<const Outer&>(back));
  EXPECT_EQ(again.out.dump(), w.out.dump());
}

TEST(JsonFields, AbsentFieldsKeepTheirDefaults) {
  Outer back;
  back.count = 5;
  const nlohmann::json j = {{"name", "n"}};  // the reader keeps a reference
  JsonReader r(j, "outer");
  VisitOuter(r, back);
  ASSERT_TRUE(r.status().ok());
  EXPECT_EQ(back.count, 5u);
  EXPECT_FALSE(back.maybe.has_value());
}

TEST(JsonFields, TheFirstBadFieldIsNamedWithItsPath) {
  const std::vector<std::pair<nlohmann::json, std::string>> cases = {
      {{{"count", 1}}, "outer.name: missing"},
      {{{"name", "n"}, {"count", -1}}, "outer.count: not a count"},
      {{{"name", "n"}, {"level", 1.5}}, "outer.level: not an integer"},
      {{{"name", "n"}, {"on", 1}}, "outer.on: not true/false"},
      {{{"name", 3}}, "outer.name: not a string"},
      {{{"name", "n"}, {"at", {1, 2}}}, "outer.at: not three numbers"},
      {{{"name", "n"}, {"inner", {{"x_mm", "far"}}}}, "outer.inner.x_mm: not a number"},
      {{{"name", "n"}, {"items", {{{"x_mm", 1}}, {{"x_mm", true}}}}},
       "outer.items[1].x_mm: not a number"},
      {{{"name", "n"}, {"items", 3}}, "outer.items: not an array"},
      {nlohmann::json::array(), "outer: not an object"},
  };
  for (const auto& [j, message] : cases) {
    Outer o;
    JsonReader r(j, "outer");
    VisitOuter(r, o);
    EXPECT_EQ(r.status().code(), absl::StatusCode::kDataLoss) << message;
    EXPECT_EQ(r.status().message(), message);
  }
}

TEST(JsonFields, TheListerKeepsTheVisitingOrderAndLeavesOutDerivedValues) {
  JsonLister l;
  VisitInner(l, static_cast<const Inner&>(Inner{2.0}));
  ASSERT_EQ(l.fields.size(), 1u);
  EXPECT_EQ(l.fields[0].key, "x_mm");
  EXPECT_EQ(l.fields[0].value, 2.0);
  JsonLister all;
  VisitOuter(all, static_cast<const Outer&>(Sample()));
  std::vector<std::string> keys;
  for (const JsonField& f : all.fields) keys.push_back(f.key);
  EXPECT_EQ(keys,
            (std::vector<std::string>{"name", "count", "level", "on", "maybe", "at", "counts"}));
}

}  // namespace
}  // namespace surfinspect
