/*
   What the tuner and the benchmarks need to know about the machine they run on, read from Linux's
   /proc and /sys: the CPU model string, the online cores and the last-level cache size. Plain C++,
   no PETSc, header only, so the plug-in and the example programs read them the same way. Each
   answer is empty or 0 where the system does not say (another OS, a container hiding /sys).
*/
#ifndef BINBCSR_MACHINE_H
#define BINBCSR_MACHINE_H

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <unistd.h>
#if defined(__x86_64__) || defined(__i386__)
  #include <cpuid.h>
  #include <emmintrin.h>
  #include <immintrin.h>
#endif

namespace binbcsr {

/* The "model name" of /proc/cpuinfo (the first core's), tabs and line ends replaced by spaces. */
inline std::string cpu_model()
{
  std::ifstream in("/proc/cpuinfo");
  std::string   line;
  while (std::getline(in, line)) {
    if (line.compare(0, 10, "model name") != 0) continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) break;
    std::string m = line.substr(colon + 1);
    while (!m.empty() && std::isspace((unsigned char)m.front())) m.erase(m.begin());
    for (char &c : m)
      if (c == '\t' || c == '\n' || c == '\r') c = ' ';
    return m;
  }
  return "";
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

} // namespace binbcsr

#endif
