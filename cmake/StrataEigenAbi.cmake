# One Eigen memory ABI for strata and everything that includes its headers.
#
# strata's own code may be built for a wider instruction set (STRATA_AVX2: -march=x86-64-v3) than
# the programs that use an installed strata (and, in this tree, than some tests). Eigen 3.4 derives its alignment from the instruction set:
# with AVX-512 it aligns heap blocks to 64 bytes with its own allocator (pointer to the malloc block
# stored just before the data) and fixed-size types to 32/64 bytes; without AVX it calls plain
# malloc/free and aligns to 16. A matrix allocated inside libstrata_core and freed by the caller
# then corrupts the heap ("double free or corruption"), and fixed-size members change layout.
#
# Pinning the bound to 16 bytes makes fixed-size layouts identical everywhere and keeps the
# assumed alignment of dynamic data at 16; forcing Eigen's own allocator on every side makes
# allocation and release compatible whatever alignment each side requests. AVX code still runs
# (unaligned loads). These are PUBLIC definitions, so they are exported with strata::core.
target_compile_definitions(strata_core PUBLIC EIGEN_MAX_ALIGN_BYTES=16 EIGEN_MALLOC_ALREADY_ALIGNED=0)
