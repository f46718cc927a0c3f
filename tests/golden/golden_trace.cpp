#include "golden_trace.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

namespace hapsim::test {

void append_cycle(GoldenTrace& trace, GoldenCycle cycle) {
  const bool all_zero =
      std::all_of(cycle.values.begin(), cycle.values.end(), [](double v) { return v == 0.0; });
  if (!all_zero || !cycle.contacts.empty()) {
    trace.cycles.push_back(std::move(cycle));
  }
}

void write_golden(const std::filesystem::path& file, const GoldenTrace& trace) {
  std::ostringstream out;
  out.precision(17);
  out << "hapsim-golden/1\n";
  out << "scene " << trace.scene << "\n";
  out << "cycles " << trace.cycle_count << "\n";
  out << "columns";
  for (const std::string& c : trace.columns) {
    out << ' ' << c;
  }
  out << "\n";
  for (const GoldenCycle& c : trace.cycles) {
    out << c.index;
    for (const double v : c.values) {
      out << ' ' << v;
    }
    out << " | " << c.contacts.size();
    for (const GoldenContact& k : c.contacts) {
      out << ' ' << k.tool << ' ' << k.body << ' ' << k.segment << ' ' << k.force_n;
    }
    out << "\n";
  }
  const std::string text = out.str();
  gzFile gz = gzopen(file.c_str(), "wb9");
  if (gz == nullptr ||
      gzwrite(gz, text.data(), static_cast<unsigned>(text.size())) !=
          static_cast<int>(text.size()) ||
      gzclose(gz) != Z_OK) {
    throw std::runtime_error(file.string() + ": cannot write");
  }
}

GoldenTrace read_golden(const std::filesystem::path& file) {
  gzFile gz = gzopen(file.c_str(), "rb");
  if (gz == nullptr) {
    throw std::runtime_error(file.string() + ": cannot open");
  }
  std::string text;
  char buffer[1 << 16];
  int n = 0;
  while ((n = gzread(gz, buffer, sizeof buffer)) > 0) {
    text.append(buffer, static_cast<std::size_t>(n));
  }
  gzclose(gz);
  if (n < 0) {
    throw std::runtime_error(file.string() + ": not a readable gzip file");
  }
  std::istringstream in(text);
  std::string line;
  std::size_t line_no = 0;
  const auto fail = [&](const std::string& what) {
    throw std::runtime_error(file.string() + ":" + std::to_string(line_no) + ": " + what);
  };
  GoldenTrace trace;
  std::string word;
  ++line_no;
  if (!std::getline(in, line) || line != "hapsim-golden/1") {
    fail("expected 'hapsim-golden/1'");
  }
  ++line_no;
  if (!std::getline(in, line) || line.rfind("scene ", 0) != 0) {
    fail("expected 'scene NAME'");
  }
  trace.scene = line.substr(6);
  ++line_no;
  if (!(in >> word >> trace.cycle_count) || word != "cycles") {
    fail("expected 'cycles N'");
  }
  std::getline(in, line);
  ++line_no;
  if (!std::getline(in, line)) {
    fail("expected 'columns ...'");
  }
  {
    std::istringstream cols(line);
    cols >> word;
    if (word != "columns") {
      fail("expected 'columns ...'");
    }
    while (cols >> word) {
      trace.columns.push_back(word);
    }
  }
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream row(line);
    GoldenCycle c;
    c.values.resize(trace.columns.size());
    if (!(row >> c.index)) {
      fail("expected a cycle index");
    }
    for (double& v : c.values) {
      if (!(row >> v)) {
        fail("expected " + std::to_string(trace.columns.size()) + " values");
      }
    }
    std::size_t count = 0;
    if (!(row >> word >> count) || word != "|") {
      fail("expected '| CONTACTS'");
    }
    c.contacts.resize(count);
    for (GoldenContact& k : c.contacts) {
      if (!(row >> k.tool >> k.body >> k.segment >> k.force_n)) {
        fail("expected tool, body, segment and force per contact");
      }
    }
    trace.cycles.push_back(std::move(c));
  }
  return trace;
}

namespace {

std::string contact_key(const GoldenContact& c) {
  return "tool " + std::to_string(c.tool) + " on body " + std::to_string(c.body) + " segment " +
         std::to_string(c.segment);
}

// Contacts of a cycle, keyed by (tool, body, segment), forces summed over repeats.
std::map<std::string, double> by_key(const GoldenCycle* c) {
  std::map<std::string, double> m;
  if (c != nullptr) {
    for (const GoldenContact& k : c->contacts) {
      m[contact_key(k)] += k.force_n;
    }
  }
  return m;
}

}  // namespace

std::string compare_golden(const GoldenTrace& expected, const GoldenTrace& actual,
                           double tolerance) {
  if (expected.columns != actual.columns) {
    return "columns differ";
  }
  if (expected.cycle_count != actual.cycle_count) {
    return "cycle count: expected " + std::to_string(expected.cycle_count) + ", got " +
           std::to_string(actual.cycle_count);
  }
  std::map<std::uint64_t, const GoldenCycle*> e;
  std::map<std::uint64_t, const GoldenCycle*> a;
  for (const GoldenCycle& c : expected.cycles) {
    e[c.index] = &c;
  }
  for (const GoldenCycle& c : actual.cycles) {
    a[c.index] = &c;
  }
  std::vector<std::uint64_t> indices;
  for (const auto& [k, v] : e) {
    indices.push_back(k);
  }
  for (const auto& [k, v] : a) {
    indices.push_back(k);
  }
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  std::string first;
  std::size_t differing = 0;
  double worst = 0.0;
  const std::vector<double> zeros(expected.columns.size(), 0.0);
  for (const std::uint64_t k : indices) {
    const GoldenCycle* ec = e.count(k) != 0 ? e[k] : nullptr;
    const GoldenCycle* ac = a.count(k) != 0 ? a[k] : nullptr;
    const std::vector<double>& ev = ec != nullptr ? ec->values : zeros;
    const std::vector<double>& av = ac != nullptr ? ac->values : zeros;
    std::string what;
    for (std::size_t i = 0; i < ev.size(); ++i) {
      const double d = std::abs(ev[i] - av[i]);
      if (!(d <= tolerance)) {
        worst = std::max(worst, d);
        if (what.empty()) {
          std::ostringstream s;
          s.precision(17);
          s << expected.columns[i] << ": expected " << ev[i] << ", got " << av[i];
          what = s.str();
        }
      }
    }
    const auto ek = by_key(ec);
    const auto ak = by_key(ac);
    for (const auto& [key, force] : ek) {
      const auto it = ak.find(key);
      if (it == ak.end()) {
        what = what.empty() ? "contact " + key + " missing" : what;
      } else if (!(std::abs(it->second - force) <= tolerance)) {
        worst = std::max(worst, std::abs(it->second - force));
        if (what.empty()) {
          std::ostringstream s;
          s.precision(17);
          s << "contact " << key << ": expected " << force << " N, got " << it->second << " N";
          what = s.str();
        }
      }
    }
    for (const auto& [key, force] : ak) {
      if (ek.count(key) == 0 && what.empty()) {
        what = "extra contact " + key;
      }
    }
    if (!what.empty()) {
      ++differing;
      if (first.empty()) {
        first = "cycle " + std::to_string(k) + ", " + what;
      }
    }
  }
  if (differing == 0) {
    return {};
  }
  std::ostringstream s;
  s << first << " (" << differing << " cycle(s) differ; largest value difference " << worst << ")";
  return s.str();
}

}  // namespace hapsim::test
