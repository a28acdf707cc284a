// compact_matrix in.bin out.bbm [bs]: a PETSc binary matrix (what the drivers write with -dump_matrix)
// in the compact form of bench_matrices.h, for scripts/gpu_check --prepare. No PETSc.
#include "bench_matrices.h"

int main(int argc, char **argv)
{
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s in.bin out.bbm [bs]\n", argv[0]);
    return 2;
  }
  const gpu_bench::BlockMatrix A = gpu_bench::read_petsc_binary(argv[1], argc > 3 ? std::atoi(argv[3]) : 3);
  gpu_bench::write_compact(A, argv[2]);
  const gpu_bench::BlockMatrix B = gpu_bench::read_compact(argv[2]);
  if (B.mbs != A.mbs || B.col != A.col || B.ptr != A.ptr) {
    std::fprintf(stderr, "%s: the compact copy does not read back\n", argv[2]);
    return 1;
  }
  std::printf("%s: %d block rows, %ld blocks -> %s\n", argv[1], A.mbs, A.nblocks(), argv[2]);
  return 0;
}
