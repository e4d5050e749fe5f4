// Shared by the peer timing harnesses: OFF input/output, a wall clock, medians, JSON.
// Header-only on purpose (each harness is one g++ invocation, see build.sh).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <time.h>

namespace harness {

// A triangle mesh as flat arrays, the layout hybridsub uses: V is n x 3, F is m x 3.
struct Mesh {
    std::vector<double> V;
    std::vector<int> F;
    int n_vertices() const { return int(V.size() / 3); }
    int n_faces() const { return int(F.size() / 3); }
};

// Read an OFF file of triangles without merging or reordering anything ('#' starts a comment),
// exactly as hybridsub._examples.read_off does.
inline Mesh read_off(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::stringstream words;
    std::string line;
    while (std::getline(in, line)) {
        auto hash = line.find('#');
        words << (hash == std::string::npos ? line : line.substr(0, hash)) << '\n';
    }
    std::string magic;
    long nv, nf, ne;
    words >> magic >> nv >> nf >> ne;
    if (magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0)
        throw std::runtime_error(path + ": not an OFF file");
    Mesh m;
    m.V.resize(3 * nv);
    for (auto& x : m.V) words >> x;
    m.F.resize(3 * nf);
    for (long f = 0; f < nf; ++f) {
        int k;
        words >> k;
        if (k != 3) throw std::runtime_error(path + ": only triangles are supported");
        words >> m.F[3 * f] >> m.F[3 * f + 1] >> m.F[3 * f + 2];
    }
    if (!words) throw std::runtime_error(path + ": truncated");
    return m;
}

// 17 significant digits: the values read back are the doubles written.
inline void write_off(const std::string& path, const Mesh& m) {
    FILE* out = std::fopen(path.c_str(), "w");
    if (!out) throw std::runtime_error("cannot write " + path);
    std::fprintf(out, "OFF\n%d %d 0\n", m.n_vertices(), m.n_faces());
    for (int i = 0; i < m.n_vertices(); ++i)
        std::fprintf(out, "%.17g %.17g %.17g\n", m.V[3 * i], m.V[3 * i + 1], m.V[3 * i + 2]);
    for (int f = 0; f < m.n_faces(); ++f)
        std::fprintf(out, "3 %d %d %d\n", m.F[3 * f], m.F[3 * f + 1], m.F[3 * f + 2]);
    std::fclose(out);
}

// Vertex pairs "i j", one per line (0-based).
inline std::vector<int> read_pairs(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::vector<int> pairs;
    int a, b;
    while (in >> a >> b) {
        pairs.push_back(a);
        pairs.push_back(b);
    }
    return pairs;
}

inline double now() {
    using clock = std::chrono::steady_clock;
    return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
}

// CPU seconds of the whole process (all its threads): on a shared machine, a single-threaded
// section's CPU time leaves out the time other processes held the core.
inline double cpu_now() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

inline double median(std::vector<double> t) {
    if (t.empty()) return 0.0;
    std::sort(t.begin(), t.end());
    size_t n = t.size();
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

inline std::string json_list(const std::vector<double>& t) {
    std::ostringstream s;
    s.precision(9);
    s << '[';
    for (size_t i = 0; i < t.size(); ++i) s << (i ? ", " : "") << t[i];
    s << ']';
    return s.str();
}

// "name": {"median": .., "min": .., "times": [..]}
inline std::string json_timing(const std::string& name, const std::vector<double>& t) {
    std::ostringstream s;
    s.precision(9);
    s << '"' << name << "\": {\"median\": " << median(t)
      << ", \"min\": " << *std::min_element(t.begin(), t.end()) << ", \"times\": " << json_list(t) << '}';
    return s.str();
}

// Linux: a /proc/self/status field ("VmRSS", "VmHWM") in bytes, or -1.
inline long status_bytes(const std::string& key) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(key + ":", 0) == 0) return std::stol(line.substr(key.size() + 1)) * 1024;
    return -1;
}

// Peak RSS growth of f(): VmHWM is reset to the current RSS first (/proc/self/clear_refs, the
// method compare.py uses for hybridsub); -1 where that is not possible.
template <class Fn>
long peak_rss_growth(Fn&& f) {
    std::ofstream reset("/proc/self/clear_refs");
    const bool ok = bool(reset << "5" << std::flush);
    const long before = status_bytes("VmRSS");
    f();
    const long peak = status_bytes("VmHWM");
    return ok && before >= 0 && peak >= 0 ? peak - before : -1;
}

// Minimal argv parsing: positional arguments and --key value options.
struct Args {
    std::vector<std::string> pos;
    std::vector<std::pair<std::string, std::string>> opt;
    Args(int argc, char** argv) {
        for (int i = 1; i < argc; ++i) {
            std::string a = argv[i];
            if (a.rfind("--", 0) == 0 && i + 1 < argc) opt.emplace_back(a.substr(2), argv[++i]);
            else pos.push_back(a);
        }
    }
    std::string get(const std::string& key, const std::string& def = "") const {
        for (auto& kv : opt)
            if (kv.first == key) return kv.second;
        return def;
    }
};

}  // namespace harness
