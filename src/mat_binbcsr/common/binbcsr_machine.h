/*
   What the tuner and the benchmarks need to know about the machine they run on, from CPUID and
   Linux's /proc and /sys: the CPU model string, the online cores and the last-level cache size. Plain C++,
   no PETSc, header only, so the plug-in and the example programs read them the same way. Each
   answer is empty or 0 where the system does not say (another OS, a container hiding /sys).
*/
#ifndef BINBCSR_MACHINE_H
#define BINBCSR_MACHINE_H

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <ctime>
#include <unistd.h>
#if defined(__linux__)
  #include <sys/mman.h>
#endif
#if defined(__x86_64__) || defined(__i386__)
  #include <cpuid.h>
  #include <emmintrin.h>
  #include <immintrin.h>
#endif

namespace binbcsr {

/* CPU seconds of this thread: on a machine shared with other work the wall clock also counts the time
   the process waits for a core, which would decide a timed choice (the tuner's, the x load trial's)
   by chance. */
inline double thread_cpu_seconds()
{
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The CPU as the tuning cache names it. On x86: the brand string of CPUID leaves 0x80000002-4 and the
   family and model of leaf 1, "AMD EPYC 9654 96-Core Processor (family 25 model 17)". The family and
   model tell apart CPUs a virtual machine gives one name: Zen 3, 4 and 5 VMs here all said "AMD
   EPYC" in /proc/cpuinfo, and their fastest layouts differ, so a cache in a home folder shared by such
   machines must not hand one's choices to another. CPUID also costs nothing, where reading
   /proc/cpuinfo took 0.4 ms on a VM (the kernel measures each core's clock for it). Elsewhere the
   "model name" of /proc/cpuinfo (the first core's). Tabs and line ends become spaces; computed once. */
inline const std::string &cpu_model()
{
  static const std::string model = [] {
    std::string m;
#if defined(__x86_64__) || defined(__i386__)
    unsigned r[4] = {0, 0, 0, 0};
    if (__get_cpuid_max(0x80000000u, nullptr) >= 0x80000004u) {
      char brand[49] = {};
      for (unsigned leaf = 0; leaf < 3; leaf++) {
        __get_cpuid(0x80000002u + leaf, &r[0], &r[1], &r[2], &r[3]);
        for (int i = 0; i < 4; i++)
          for (int b = 0; b < 4; b++) brand[16 * leaf + 4 * i + b] = (char)((r[i] >> (8 * b)) & 0xff);
      }
      m = brand;
    }
    if (__get_cpuid(1, &r[0], &r[1], &r[2], &r[3])) {
      const unsigned base = (r[0] >> 8) & 0xf, ext_family = (r[0] >> 20) & 0xff;
      const unsigned model  = ((r[0] >> 4) & 0xf) | (base == 6 || base == 15 ? ((r[0] >> 16) & 0xf) << 4 : 0);
      const unsigned family = base == 15 ? base + ext_family : base;
      while (!m.empty() && std::isspace((unsigned char)m.back())) m.pop_back();
      m += " (family " + std::to_string(family) + " model " + std::to_string(model) + ")";
    }
#else
    std::ifstream in("/proc/cpuinfo");
    std::string   line;
    while (std::getline(in, line)) {
      if (line.compare(0, 10, "model name") != 0) continue;
      const size_t colon = line.find(':');
      if (colon != std::string::npos) m = line.substr(colon + 1);
      break;
    }
#endif
    while (!m.empty() && std::isspace((unsigned char)m.front())) m.erase(m.begin());
    while (!m.empty() && std::isspace((unsigned char)m.back())) m.pop_back();
    for (char &c : m)
      if (c == '\t' || c == '\n' || c == '\r') c = ' ';
    return m;
  }();
  return model;
}

inline long online_cpus()
{
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? n : 1;
}

/* Bytes of one "size" file of /sys/.../cache/indexN: "32768K", "1024K", "32M" or a plain number. */
inline long parse_cache_size(const std::string &s)
{
  char *end = nullptr;
  long  v   = std::strtol(s.c_str(), &end, 10);
  if (v <= 0 || end == s.c_str()) return 0;
  if (*end == 'K' || *end == 'k') v <<= 10;
  else if (*end == 'M' || *end == 'm') v <<= 20;
  else if (*end == 'G' || *end == 'g') v <<= 30;
  return v;
}

/* The data or unified cache of the highest level cpu0 has, in bytes (/sys/devices/system/cpu/cpu0/
   cache/index*: level, type, size); 0 when the system does not say. sysconf's _SC_LEVEL3_CACHE_SIZE
   is not used: glibc derives it from CPUID, which a virtual machine may report wrongly (an EPYC VM
   with a 32 MiB L3 answered 336 MB). */
inline long last_level_cache_bytes()
{
  long best_level = 0, bytes = 0;
  for (int i = 0; i < 16; i++) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(i) + "/";
    std::ifstream     lf(dir + "level"), tf(dir + "type"), sf(dir + "size");
    long              level = 0;
    std::string       type, size;
    if (!(lf >> level) || !(tf >> type) || !(sf >> size)) continue;
    if (type == "Instruction") continue;
    const long b = parse_cache_size(size);
    if (b > 0 && level > best_level) {
      best_level = level;
      bytes      = b;
    }
  }
  return bytes;
}

#if defined(__x86_64__) || defined(__i386__)
/* clflushopt (CPUID.7.0:EBX bit 23): clflush's weakly ordered form, whose flushes overlap. */
inline bool has_clflushopt()
{
  static const bool has = [] {
    unsigned a, b, c, d;
    return __get_cpuid_count(7, 0, &a, &b, &c, &d) && ((b >> 23) & 1u);
  }();
  return has;
}

__attribute__((target("clflushopt"))) inline void flush_lines_opt(const char *c, size_t bytes)
{
  for (size_t i = 0; i < bytes; i += 64) _mm_clflushopt((void *)(c + i));
  _mm_clflushopt((void *)(c + bytes - 1));
}
#endif

/* Writes back and drops the cache lines of [p, p + bytes) from every cache level, so that the next
   pass reads them from memory. clflushopt where the CPU has it: each clflush waits for the one before,
   and on a Xeon VM (family 6 model 207) flushing a 24 MB tuning sample before each of 22 timed
   products took 1.6 s against 49 ms of products. clflush (SSE2, every x86-64) otherwise; a no-op
   off x86. */
inline void evict_from_caches(const void *p, size_t bytes)
{
#if defined(__x86_64__) || defined(__i386__)
  if (!bytes) return;
  const char *c = (const char *)p;
  if (has_clflushopt()) flush_lines_opt(c, bytes);
  else {
    for (size_t i = 0; i < bytes; i += 64) _mm_clflush(c + i);
    _mm_clflush(c + bytes - 1);
  }
  _mm_mfence();
#else
  (void)p;
  (void)bytes;
#endif
}

/* CPU seconds of one read pass over words [p, p + n) (their xor, kept from the optimiser). */
inline double read_pass_seconds(const std::uint64_t *p, size_t n)
{
  const double  t0 = thread_cpu_seconds();
  std::uint64_t x  = 0;
  for (size_t i = 0; i < n; i++) x ^= p[i];
  const double           t    = thread_cpu_seconds() - t0;
  volatile std::uint64_t sink = x;
  (void)sink;
  return t;
}

/* Whether an array of `bytes` stays in the caches from one read pass to the next, measured. A virtual
   machine reports its host's last-level cache, which it shares with the host's other guests: a 2-core
   Xeon VM (family 6 model 167) said 480 MiB, while a 67 MB matrix was read from memory at every
   product there (the tuner, trusting the figure, timed its sample in cache and chose layouts 1.2-1.3x
   slower than the best). Arrays of 1 MiB, 2 MiB, ... up to `bytes` are read again and again after a
   first pass (at least three times and 2 ms); one stays when the fastest pass reads it at 1.3x the
   memory rate, the fastest of passes over 4 MiB just flushed from the caches (three beside each size),
   and the first size that does not ends the search. On that VM a warm pass
   read 1.5-1.7x the memory rate up to 32 MiB, 1.06-1.25x at 64 MiB and 1.0-1.05x beyond. No more than
   `limit` bytes are ever tried (what the system claims; a larger array is not resident). The answers
   are kept for the process: the search costs a few passes over up to the first size that misses (64
   MiB on that VM: 35-100 ms, most of it the first touch of the pages). */
struct CacheResidency {
  size_t resident = 0, missed = SIZE_MAX; /* the largest size seen to stay, the smallest seen not to */
};
inline CacheResidency &cache_residency()
{
  static CacheResidency r;
  return r;
}

inline bool stays_in_cache(size_t bytes, size_t limit)
{
  size_t &resident = cache_residency().resident, &missed = cache_residency().missed;
  if (bytes > limit) return false;
  size_t top = (size_t)1 << 20; /* the size measured for `bytes`: the power of two above it */
  while (top < bytes) top <<= 1;
  if (top <= resident) return true;
  if (top >= missed) return false;
  const size_t align = (size_t)2 << 20, alloc = (std::max(top, (size_t)4 << 20) + align - 1) / align * align;
  std::uint64_t *buf = (std::uint64_t *)std::aligned_alloc(align, alloc);
  if (!buf) return false;
#if defined(MADV_HUGEPAGE)
  madvise(buf, alloc, MADV_HUGEPAGE); /* fewer page faults to fill it, no page walks to read it */
#endif
  const size_t ref = (size_t)4 << 20; /* the memory reference: 4 MiB, flushed before each pass */
  std::memset(buf, 1, ref);
  double memory_rate = 0; /* the fastest flushed pass of the search: a slow moment only lowers a rate */
  bool   stays       = true;
  size_t filled      = ref;
  for (size_t s = (size_t)1 << 20; s <= top; s <<= 1) {
    if (s <= resident) continue;
    if (s > limit) { /* beyond the claim (bytes is below it, the power of two above is not) */
      stays = false;
      break;
    }
    if (s > filled) {
      std::memset((char *)buf + filled, 1, s - filled);
      filled = s;
    }
    /* the reference beside each size, and warm passes for at least 2 ms: on a VM a slow moment of a
       few milliseconds covered all three passes of one measurement, and the answer moved between 1
       and 64 MiB from one process to the next (the reference between 14 and 21 GB/s) */
    for (int k = 0; k < 3; k++) {
      evict_from_caches(buf, ref);
      memory_rate = std::max(memory_rate, (double)ref / read_pass_seconds(buf, ref / 8));
    }
    read_pass_seconds(buf, s / 8);
    double warm = 1e30, spent = 0;
    for (int k = 0; k < 64 && (k < 3 || spent < 2e-3); k++) {
      const double t = read_pass_seconds(buf, s / 8);
      warm           = std::min(warm, t);
      spent += t;
    }
    if ((double)s / warm < 1.3 * memory_rate) {
      missed = std::min(missed, s);
      stays  = false;
      break;
    }
    resident = s;
  }
  std::free(buf);
  return stays;
}

/* The largest power of two of bytes that stays in the caches, at most `limit`; 0 when not even 1 MiB
   does. One search of stays_in_cache up to `limit` finds it: the search records each size it passes. */
inline size_t resident_cache_bytes(size_t limit)
{
  stays_in_cache(limit, limit);
  size_t s = cache_residency().resident;
  while (s > limit) s >>= 1; /* an earlier search with a larger limit may have gone past this one */
  return s;
}

} // namespace binbcsr

#endif
