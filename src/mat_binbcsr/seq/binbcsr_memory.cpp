/* Allocation of the arrays that MatMult streams (values, slot columns).

   Out of cache the product walks hundreds of MB in one pass, and the x gather touches a few MB at
   random: with 4 KiB pages every 4 KiB of stream costs a TLB walk and the gather misses the TLB
   often. Linux hands out 2 MiB pages for a region marked MADV_HUGEPAGE (transparent huge pages in
   "madvise" mode, Debian's default) if the region is 2 MiB aligned and first touched after the
   advice; so large arrays are aligned to 2 MiB, advised, then zeroed (the first touch). Small arrays,
   and systems without the advice, get ordinary 64-byte aligned memory. PETSc's malloc cannot pass the
   alignment through, so these arrays have their own pair of calls (free with the matching one). */
#include "binbcsr.h"
#include <cstdlib>
#include <cstring>
#if defined(__linux__)
  #include <sys/mman.h>
#endif

static const size_t kHugePage = (size_t)2 << 20;

PetscErrorCode MatSeqBinBCSRStreamMalloc(size_t bytes, void **p)
{
  void        *q     = nullptr;
  const bool   huge  = bytes >= 2 * kHugePage;
  const size_t align = huge ? kHugePage : 64;
  const size_t size  = (PetscMax(bytes, (size_t)1) + align - 1) / align * align; /* aligned_alloc wants a multiple */

  PetscFunctionBegin;
  PetscCheck(posix_memalign(&q, align, size) == 0 && q, PETSC_COMM_SELF, PETSC_ERR_MEM, "Out of memory allocating %zu bytes for the bin layout", bytes);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (huge) (void)madvise(q, size, MADV_HUGEPAGE); /* advice only: ignored where THP is off */
#endif
  std::memset(q, 0, size);
  *p = q;
  PetscFunctionReturn(0);
}

PetscErrorCode MatSeqBinBCSRStreamFree(void *p)
{
  PetscFunctionBegin;
  std::free(*(void **)p);
  *(void **)p = nullptr;
  PetscFunctionReturn(0);
}
