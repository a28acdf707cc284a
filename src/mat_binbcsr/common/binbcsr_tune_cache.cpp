/* The tuning cache file of MATSEQBINBCSR: one text line per (machine, matrix class),

     # petscbinbcsr tune cache v5
     <machine key> TAB <matrix class> TAB <bin width> <streams> <body set> <prefetch bytes> <x load>

   read whole and rewritten whole (a temporary file renamed over the old one). The file only saves
   time: whatever is wrong with it makes the tuner measure again, never fail or use a bad layout.
   The version counts the tuner's way of measuring, not only the format: a file written by an older
   tuner (v1 timed its sample partly in cache, and chose bin width 8 with 4 streams for a 48^3 stencil
   that ran 2.3x slower with it) holds choices this one would not make, so it is dropped quietly and
   measured again. The version also moves when bodies change what is fastest: v3 came with the
   hand-written AVX2 bodies, after which a Zen 3 core ran the 48^3 stencil's whole single product
   fastest at bin width 4, where v2 files held 16 (measured with the compiler-vectorised ones); v4 added
   the software prefetch distance, which v3 choices were timed at 4096 bytes only; v5 the x load
   (loads or gather, MatBinBCSRSetXLoad), which v4 choices were timed with loads only.
   Since then the machine key ends with the kernel id (BINBCSR_KERNEL_ID, a hash of the bodies', the
   layout build's and the tuner's sources made by the build): a library whose kernels changed takes none
   of the choices an earlier one made, and its first store drops them. Without it a choice stayed in the
   file for good: on a Zen 5 VM the 32^3 stencil kept bin width 4 with the AVX2 body, chosen by an earlier
   build, 1.2-1.4x slower than the width 8 AVX-512 body that every new tuning chose. */
#include "binbcsr_tune.h"
#include <petscbinbcsr.h> /* MatBinBCSRXLoads */
#include "binbcsr_machine.h"
#include "../kernels/binbcsr_dispatch.h"
#include "binbcsr_kernel_id.h" /* generated: BINBCSR_KERNEL_ID */
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

static const char *const cache_header      = "# petscbinbcsr tune cache v5";
static const char *const cache_header_stem = "# petscbinbcsr tune cache v"; /* of every version */

/* The machine without the kernel id: CPU, cores and the best body set. */
static const std::string &MachineStem(void)
{
  static const char       *bodies = binbcsr::body_set_name(binbcsr::best_body_set());
  const std::string       &model  = binbcsr::cpu_model();
  static const std::string stem   = (model.empty() ? std::string("unknown cpu") : model) + " | " +
                                  std::to_string(binbcsr::online_cpus()) + " cores | " + bodies;
  return stem;
}

const std::string &BinBCSRTuneMachineKey(void)
{
  static const std::string key = MachineStem() + " | kernels " + BINBCSR_KERNEL_ID;
  return key;
}

/* Whether an entry (machine TAB class) is this machine's from another kernel id, or from before the
   id was in the key. */
static bool StaleForThisMachine(const std::string &entry)
{
  const std::string machine = entry.substr(0, entry.find('\t')), &stem = MachineStem();
  if (machine == BinBCSRTuneMachineKey()) return false;
  return machine == stem || machine.rfind(stem + " | kernels ", 0) == 0;
}

std::string BinBCSRTuneCachePath(void)
{
  const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
  std::string dir;
  if (xdg && xdg[0] == '/') dir = xdg; /* the XDG rule: a relative value is ignored */
  else if (home && home[0]) dir = std::string(home) + "/.cache";
  else return "";
  return dir + "/petscbinbcsr/tune.txt";
}

/* A file of this size is none the tuner wrote (a line per matrix class and machine, under 200 bytes) */
static const off_t cache_max_bytes = 1 << 20;

/* Why what st describes is no cache file (no regular file: a folder, a FIFO, a device; or one far
   larger than a cache), or nullptr when it may be one. */
static const char *NotCacheFile(const struct stat &st)
{
  if (!S_ISREG(st.st_mode)) return "not a regular file";
  if (st.st_size > cache_max_bytes) return "larger than 1 MiB";
  return nullptr;
}

/* The whole file, read without blocking: a FIFO at the path would block an open for reading until a
   writer came, and a device (a link to /dev/zero) would never end. Returns 0 (text holds the file), 1
   when there is nothing to read (no file, or unreadable), -1 when the path is no regular file or one
   too large (why says which). */
static int ReadCacheText(const std::string &path, std::string &text, std::string &why)
{
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return 1;
  struct stat st;
  int         status = 0;
  if (fstat(fd, &st) != 0) status = 1;
  else if (const char *no = NotCacheFile(st)) why = no, status = -1;
  else {
    text.resize((size_t)st.st_size);
    size_t got = 0;
    while (got < text.size()) {
      const ssize_t n = read(fd, &text[got], text.size() - got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += (size_t)n;
    }
    text.resize(got); /* a file cut short while read: what was there (the parse judges it) */
  }
  close(fd);
  return status;
}

/* Every entry of the file; false when the file exists but does not parse, or is no regular file of a
   cache's size (why says where). */
static bool ReadCache(const std::string &path, std::map<std::string, BinBCSRTuneChoice> &entries,
                      std::string &why)
{
  std::string text, line;
  const int   status = ReadCacheText(path, text, why);
  if (status > 0) return true; /* no file yet (or unreadable): nothing cached */
  if (status < 0) return false;
  std::istringstream in(text);
  if (std::getline(in, line) && line != cache_header && line.rfind(cache_header_stem, 0) == 0) {
    PetscCallAbort(PETSC_COMM_SELF, PetscInfo(nullptr,
                                              "Tuning cache %s is from another tuner version (\"%s\"): "
                                              "not used, measured again\n",
                                              path.c_str(), line.c_str()));
    return true; /* another version's choices: none cached */
  }
  if (line != cache_header) {
    why = "first line is not \"" + std::string(cache_header) + "\"";
    return false;
  }
  for (int n = 2; std::getline(in, line); n++) {
    const size_t t1 = line.find('\t'), t2 = t1 == std::string::npos ? t1 : line.find('\t', t1 + 1);
    if (line.empty()) continue;
    if (t2 == std::string::npos || t1 == 0 || t2 == t1 + 1) {
      why = "line " + std::to_string(n) + " has no machine, class and choice";
      return false;
    }
    std::istringstream v(line.substr(t2 + 1));
    long               bw = 0, streams = 0, prefetch = -1;
    std::string        body, xload, rest;
    int                kernel = -1, xl = -1;
    if (v >> bw >> streams >> body >> prefetch >> xload) {
      for (int k = 0; k <= (int)MAT_BINBCSR_XLOAD_GATHER; k++)
        if (xload == MatBinBCSRXLoads[k]) xl = k;
      for (int k = 0; k <= (int)binbcsr::BodySet::AVX512; k++)
        if (body == binbcsr::body_set_name((binbcsr::BodySet)k) &&
            binbcsr::body_set_available((binbcsr::BodySet)k))
          kernel = k;
    }
    if (kernel < 0 || xl < 0 || (v >> rest) || bw < 1 || bw > 1024 ||
        (streams != 1 && streams != 2 && streams != 4 && streams != 8) || prefetch < 0 || prefetch > 65536 ||
        prefetch % 64) {
      why =
        "line " + std::to_string(n) + ": choice \"" + line.substr(t2 + 1) +
        "\" is not a bin width in [1, 1024], streams 1, 2, 4 or 8, a body set this CPU has and a prefetch "
        "distance (a multiple of 64 in [0, 65536]) and an x load (loads or gather)";
      return false;
    }
    entries[line.substr(0, t2)] =
      BinBCSRTuneChoice{(PetscInt)bw, (PetscInt)streams, (PetscInt)kernel, (PetscInt)prefetch, (PetscInt)xl};
  }
  return true;
}

/* not_file: the path is there but is no regular file (a directory, a FIFO, a device) or one far larger
   than a cache, which a store leaves alone */
static PetscErrorCode WarnCorrupt(const std::string &path, const std::string &why, bool not_file)
{
  static bool warned = false;

  PetscFunctionBegin;
  PetscCall(PetscInfo(nullptr, "Ignoring the tuning cache %s: %s\n", path.c_str(), why.c_str()));
  if (!warned && not_file)
    PetscCall(PetscFPrintf(PETSC_COMM_SELF, PETSC_STDERR,
                           "petscbinbcsr: ignoring the tuning cache %s (%s); tuning choices are not kept "
                           "(-mat_binbcsr_tune_cache 0 stops looking)\n",
                           path.c_str(), why.c_str()));
  else if (!warned)
    PetscCall(PetscFPrintf(
      PETSC_COMM_SELF, PETSC_STDERR,
      "petscbinbcsr: ignoring the corrupt tuning cache %s (%s); it is rewritten by the next tuning\n",
      path.c_str(), why.c_str()));
  warned = true;
  PetscFunctionReturn(0);
}

/* The file as last read by this process, with what identifies that version of it: a scene builds
   several matrices (the cloth five), and reading and parsing the file again for each took 0.1-0.4 ms
   on a VM. A store renames a new file over the old one, so a new inode (or size or mtime) means
   another version, written by this process or another one. */
struct CacheMemo {
  std::string                              path;
  bool                                     valid = false, parsed = false, not_file = false;
  dev_t                                    dev   = 0;
  ino_t                                    ino   = 0;
  off_t                                    size  = 0;
  struct timespec                          mtime = {0, 0};
  std::map<std::string, BinBCSRTuneChoice> entries;
  std::string                              why;
};

/* The parsed file (memo.parsed false: it does not parse, memo.why says why); no file: no entries. */
static const CacheMemo &CachedFile(const std::string &path)
{
  static CacheMemo memo;
  struct stat      st;
  if (stat(path.c_str(), &st) != 0) {
    memo        = CacheMemo();
    memo.parsed = true;
    return memo; /* no file: nothing cached, and nothing kept for a file that appears later */
  }
  if (const char *no = NotCacheFile(st)) {
    memo          = CacheMemo();
    memo.not_file = true;
    memo.why      = no;
    return memo;
  }
  if (memo.valid && memo.path == path && memo.dev == st.st_dev && memo.ino == st.st_ino &&
      memo.size == st.st_size && memo.mtime.tv_sec == st.st_mtim.tv_sec &&
      memo.mtime.tv_nsec == st.st_mtim.tv_nsec)
    return memo;
  memo        = CacheMemo();
  memo.parsed = ReadCache(path, memo.entries, memo.why);
  memo.path   = path;
  memo.dev    = st.st_dev;
  memo.ino    = st.st_ino;
  memo.size   = st.st_size;
  memo.mtime  = st.st_mtim;
  memo.valid  = true;
  return memo;
}

PetscErrorCode BinBCSRTuneCacheLookup(const std::string &key, BinBCSRTuneChoice *c, PetscBool *found)
{
  std::string path = BinBCSRTuneCachePath();

  PetscFunctionBegin;
  *found = PETSC_FALSE;
  if (path.empty()) PetscFunctionReturn(0);
  const CacheMemo &file = CachedFile(path);
  if (!file.parsed) {
    PetscCall(WarnCorrupt(path, file.why, file.not_file));
    PetscFunctionReturn(0);
  }
  auto it = file.entries.find(key);
  if (it == file.entries.end()) PetscFunctionReturn(0);
  *c     = it->second;
  *found = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* mkdir -p of the folders above path; false if one cannot be made. */
static bool MakeParents(const std::string &path)
{
  for (size_t p = path.find('/', 1); p != std::string::npos; p = path.find('/', p + 1)) {
    const std::string d = path.substr(0, p);
    if (mkdir(d.c_str(), 0755) != 0 && errno != EEXIST) return false;
  }
  return true;
}

PetscErrorCode BinBCSRTuneCacheStore(const std::string &key, const BinBCSRTuneChoice &c)
{
  static unsigned long                     serial = 0;
  std::map<std::string, BinBCSRTuneChoice> entries;
  std::string                              why, path = BinBCSRTuneCachePath();

  PetscFunctionBegin;
  if (path.empty()) PetscFunctionReturn(0);
  struct stat st;
  /* no regular file (a folder, a FIFO, a device) or one far larger than a cache: someone else's, left
     alone (the lookup warned that choices are not kept) */
  if (stat(path.c_str(), &st) == 0 && NotCacheFile(st)) {
    PetscCall(PetscInfo(nullptr, "Not storing in %s: no regular file of a cache's size\n", path.c_str()));
    PetscFunctionReturn(0);
  }
  if (!ReadCache(path, entries, why)) entries.clear();  /* a corrupt file is replaced (the lookup warned) */
  for (auto it = entries.begin(); it != entries.end();) /* other kernels' choices for this machine */
    it = StaleForThisMachine(it->first) ? entries.erase(it) : std::next(it);
  entries[key] = c;
  if (!MakeParents(path)) {
    PetscCall(PetscInfo(nullptr, "Cannot create the folder of the tuning cache %s: %s\n", path.c_str(),
                        strerror(errno)));
    PetscFunctionReturn(0);
  }
  const std::string tmp = path + ".tmp." + std::to_string((long)getpid()) + "." + std::to_string(serial++);
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << cache_header << "\n";
    for (const auto &[k, v] : entries)
      out << k << "\t" << v.bw << " " << v.streams << " "
          << binbcsr::body_set_name((binbcsr::BodySet)v.kernel) << " " << v.prefetch << " "
          << MatBinBCSRXLoads[v.xload] << "\n";
    out.close();
    if (!out) {
      PetscCall(PetscInfo(nullptr, "Cannot write the tuning cache %s\n", tmp.c_str()));
      std::remove(tmp.c_str());
      PetscFunctionReturn(0);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    PetscCall(PetscInfo(nullptr, "Cannot rename %s to %s: %s\n", tmp.c_str(), path.c_str(), strerror(errno)));
    std::remove(tmp.c_str());
  }
  PetscFunctionReturn(0);
}
