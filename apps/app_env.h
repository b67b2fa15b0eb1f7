/* apps: process environment of the fcm programs (not part of the library). */
#ifndef FCM_APP_ENV_H
#define FCM_APP_ENV_H

/** Make the program behave on shared machines and use the CPU's BLAS kernels; call it first
 * in main().
 *
 * Idle OpenMP threads spin by default (libgomp: about 300,000 polls before sleeping at
 * every barrier), which costs little on idle cores but, when the cores are busy with
 * other work, burns the time slices the working threads need: a MINRES solve with many
 * short parallel regions ran 20-30x slower beside a load of 8 on 2 cores. Sleeping at once
 * (OMP_WAIT_POLICY=passive) avoids that, but then every parallel region after a sequential
 * stretch waits for its threads to wake, which on idle cores makes short regions slower.
 * The programs run between the two: a waiting thread polls 10,000 times before it sleeps
 * (GOMP_SPINCOUNT=10000), unless the user has set one of OMP_WAIT_POLICY, GOMP_SPINCOUNT and
 * KMP_BLOCKTIME (OMP_WAIT_POLICY=passive on machines kept busy by other work,
 * OMP_WAIT_POLICY=active on dedicated cores; lib/docs/performance.md, "OpenMP waiting").
 *
 * An OpenBLAS older than the CPU runs generic kernels (fcm_blas_info_get(): Debian 12's
 * OpenBLAS runs SSE3 kernels on recent AVX-512 CPUs, DGEMM and so CHOLMOD several times
 * slower). When it does, and the user has set no OPENBLAS_CORETYPE, the programs select the
 * CPU's kernels with OPENBLAS_CORETYPE and say so in one line on stderr;
 * FCM_BLAS_CORETYPE=keep keeps the kernels OpenBLAS chose.
 *
 * Memory the program touches for the first time costs a page fault per 4 KiB page, which on
 * virtual machines can cost several times the page's zero fill, and glibc gives blocks of 128
 * KiB and more back to the kernel when they are freed, so that a cut's new arrays fault in
 * again. Unless the user has set GLIBC_TUNABLES (an empty value keeps glibc's defaults), the
 * programs run with glibc.malloc.hugetlb=1 (malloc advises its heap for transparent huge pages,
 * where the kernel offers them on request: they fault in 2 MiB at a time),
 * glibc.malloc.mmap_max=0 (every block comes from the heap, none is mapped alone) and
 * glibc.malloc.trim_threshold=4294967296 (freed memory stays with the process up to 4 GiB at the
 * heap's top), so that freed arrays are used again without faults (lib/docs/performance.md,
 * "Page faults").
 *
 * The runtimes read their environment when they are loaded, before main(), so setting the
 * variables here would come too late (and a .preinit_array function cannot set them either:
 * glibc installs the environment after it). Instead this sets them and re-executes the
 * program once (/proc/self/exe, same arguments, Linux only); the new process finds them set
 * and goes on. Nothing happens under valgrind (its preload library in LD_PRELOAD: a
 * re-executed child would escape the tool), and when the re-execution fails the program
 * continues as it started. Returns only when no re-execution took place. */
void app_env_init(int argc, char **argv);

/** app_env_init() for the BLAS kernels only, leaving the OpenMP waiting and malloc as the
 * program was started with (benchmarks that measure the policies themselves). */
void app_env_init_blas(int argc, char **argv);

#endif /* FCM_APP_ENV_H */
