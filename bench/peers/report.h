// The comparison table of bench/peers_bench.cpp: timing helpers, one row per
// comparison (ours, the peer, their ratio, an agreement check and the row's
// goal, marked met or not met from the measured numbers), and the machine
// description written with it.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace surfinspect::bench {

// Median wall time of `reps` calls to f(), seconds. One untimed warm-up call
// first when `warm_up` (page faults, lazy BVH commits, connection setup).
template <class F>
double MedianSeconds(int reps, bool warm_up, F&& f) {
  if (warm_up) f();
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Medians of a() and b() timed alternately (a, b, a, b, ...), so a change in
// the machine's load during the run hits both sides alike.
template <class A, class B>
std::pair<double, double> MedianSecondsInterleaved(int reps, bool warm_up, A&& a, B&& b) {
  if (warm_up) a(), b();
  std::vector<double> ta, tb;
  for (int i = 0; i < reps; ++i) {
    ta.push_back(MedianSeconds(1, false, a));
    tb.push_back(MedianSeconds(1, false, b));
  }
  std::sort(ta.begin(), ta.end());
  std::sort(tb.begin(), tb.end());
  return {ta[ta.size() / 2], tb[tb.size() / 2]};
}

inline std::string Fmt(const char* fmt, double v) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// "12.3 ms" / "1.23 s" / "45 µs".
inline std::string Time(double s) {
  if (s >= 1.0) return Fmt("%.2f s", s);
  if (s >= 1e-3) return Fmt(s >= 0.1 ? "%.0f ms" : "%.1f ms", 1e3 * s);
  return Fmt("%.0f µs", 1e6 * s);
}

struct Row {
  std::string what;
  std::string ours;
  std::string peer;   // "skipped (...)" when the peer is not installed
  std::string ratio;  // peer time / our time, or "—"
  std::string agreement;
  std::string goal;  // the row's target, in words
  std::string met;   // "met" / "**not met**" / "—"
};

inline std::string Verdict(bool met) { return met ? "met" : "**not met**"; }

// A second table of rows without a goal (scaling).
struct ScalingRow {
  std::string what;
  std::string ours;
  std::string peer;
  std::string note;
};

inline std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  return "unknown CPU";
}

inline std::string MarkdownTable(const std::vector<std::string>& header,
                                 const std::vector<std::vector<std::string>>& rows) {
  std::string out = "|";
  for (const auto& h : header) out += " " + h + " |";
  out += "\n|";
  for (std::size_t i = 0; i < header.size(); ++i) out += "---|";
  out += "\n";
  for (const auto& r : rows) {
    out += "|";
    for (const auto& c : r) out += " " + c + " |";
    out += "\n";
  }
  return out;
}

inline std::string RenderRows(const std::vector<Row>& rows) {
  std::vector<std::vector<std::string>> cells;
  for (const Row& r : rows)
    cells.push_back({r.what, r.ours, r.peer, r.ratio, r.agreement, r.goal, r.met});
  return MarkdownTable(
      {"Comparison", "Ours", "Peer", "Peer / ours", "Agreement", "Goal", "Goal met"}, cells);
}

inline std::string RenderScaling(const std::vector<ScalingRow>& rows) {
  std::vector<std::vector<std::string>> cells;
  for (const ScalingRow& r : rows) cells.push_back({r.what, r.ours, r.peer, r.note});
  return MarkdownTable({"Scaling", "Ours", "Open3D", "Note"}, cells);
}

inline unsigned CoreCount() { return std::max(1u, std::thread::hardware_concurrency()); }

}  // namespace surfinspect::bench
