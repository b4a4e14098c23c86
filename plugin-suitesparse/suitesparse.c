/*
 * suitesparse.c -- the SuiteSparse plugin: four backends, one per library.
 *
 *   suitesparse.umfpack  general sparse LU          solve.sparse (and .spd)
 *   suitesparse.cholmod  supernodal sparse Cholesky solve.sparse.spd
 *   suitesparse.klu      LU for circuit matrices    solve.sparse
 *   suitesparse.spqr     sparse QR, least squares   solve.rect
 *
 * SILC runs init once per context that loads the module and shutdown once per
 * context closed, while dlopen shares one copy of the module: so the library
 * state (one cholmod_common, the symbolic caches) is started by the first
 * init and finished by the last shutdown.
 *
 * Threads: UMFPACK, CHOLMOD and SPQR spend their time in BLAS, which is
 * OpenBLAS here (Debian's libblas.so.3 alternative).  set_threads finds
 * openblas_set_num_threads in the BLAS our libraries already loaded and calls
 * it; with another BLAS the call is a no-op.  KLU is sequential.  CHOLMOD's
 * own OpenMP regions have a thread count fixed at its build; at 1 thread
 * they are kept on the calling thread (ss_cholmod_factorize).
 */
#include "ss.h"

#include "common/blas_threads.h"

#include <pthread.h>
#include <string.h>

const silc_host_api *ss_host;

/* Contexts holding the module (init minus shutdown), under users_mutex. */
static int ss_users;
static pthread_mutex_t users_mutex = PTHREAD_MUTEX_INITIALIZER;

#define SS_STR2(x) #x
#define SS_STR(x) SS_STR2(x)
#define SS_VERSION                                                                            \
    "1.0 SuiteSparse " SS_STR(SUITESPARSE_MAIN_VERSION) "." SS_STR(SUITESPARSE_SUB_VERSION) "." \
        SS_STR(SUITESPARSE_SUBSUB_VERSION)

/* Every solve runs with the libraries' large blocks on huge pages when
 * suitesparse.huge_pages says so (ss_alloc.c). */
static int umfpack_run(silc_call *call)
{
    return ss_with_huge_pages(call, ss_umfpack_solve);
}
static int cholmod_run(silc_call *call)
{
    return ss_with_huge_pages(call, ss_cholmod_solve);
}
static int klu_run(silc_call *call)
{
    return ss_with_huge_pages(call, ss_klu_solve);
}
static int spqr_run(silc_call *call)
{
    return ss_with_huge_pages(call, ss_spqr_solve);
}

static const silc_op_entry umfpack_ops[SILC_OP_COUNT] = {
    [SILC_OP_SOLVE] = {umfpack_run, ss_umfpack_accepts}};
static const silc_op_entry cholmod_ops[SILC_OP_COUNT] = {
    [SILC_OP_SOLVE] = {cholmod_run, ss_cholmod_accepts}};
static const silc_op_entry klu_ops[SILC_OP_COUNT] = {
    [SILC_OP_SOLVE] = {klu_run, ss_klu_accepts}};
static const silc_op_entry spqr_ops[SILC_OP_COUNT] = {
    [SILC_OP_SOLVE] = {spqr_run, ss_spqr_accepts}};

static const silc_backend ss_backends[] = {
    {"umfpack", "UMFPACK multifrontal sparse LU (square sparse systems)", SILC_OP_COUNT,
     umfpack_ops},
    {"cholmod", "CHOLMOD supernodal sparse Cholesky (symmetric positive definite)",
     SILC_OP_COUNT, cholmod_ops},
    {"klu", "KLU sparse LU for circuit-like matrices, fast refactor", SILC_OP_COUNT, klu_ops},
    {"spqr", "SuiteSparseQR multifrontal sparse QR (least squares, rank-revealing)",
     SILC_OP_COUNT, spqr_ops},
};

static const silc_option_spec ss_options[] = {
    {"condest", SILC_OPT_STRING, "true",
     "1-norm condition estimate by Hager/Higham (4 column solves, once per factorization): "
     "true (auto means the same), false (none; the libraries' cheap pivot ratio is shown, "
     "labelled, never as the estimate)"},
    {"umfpack_irstep", SILC_OPT_INT, "2", "UMFPACK: maximum steps of iterative refinement"},
    {"huge_pages", SILC_OPT_STRING, "auto",
     "auto: the libraries' blocks of 4 MiB and more on transparent huge pages (fewer page faults "
     "and TLB misses; only where the kernel has them, and only if the program has not set "
     "SuiteSparse_config's allocator itself), off: libc's malloc"},
    {"spqr_tol", SILC_OPT_DOUBLE, "-2",
     "SPQR: columns of 2-norm <= tol count as zero (rank detection); -2 = SPQR's default "
     "20*(m+n)*eps*max column norm, -1 = none"},
};

static blas_threads_fn blas_set_threads;

static void find_blas_threads(void)
{
    blas_set_threads = blas_threads_find((const void *)&ss_host);
    ss_host->log(3, "suitesparse: openblas_set_num_threads %s",
                 blas_set_threads ? "found: set_threads controls BLAS"
                                  : "not found: set_threads does nothing");
}

static void ss_set_threads(int nthreads)
{
    if (nthreads < 1) return;
    if (blas_set_threads) blas_set_threads(nthreads);
    ss_set_omp_threads(nthreads);
}

static void ss_shutdown(void)
{
    pthread_mutex_lock(&users_mutex);
    if (ss_users > 0 && --ss_users == 0) ss_finish();
    pthread_mutex_unlock(&users_mutex);
}

/* UMFPACK, CHOLMOD and KLU solve complex systems (ss_complex.c); SPQR's
 * complex least squares is not wired, so its bit is left out and the
 * dispatcher passes it over for complex values. */
static const uint32_t ss_complex_ops[] = {
    SILC_COMPLEX_OPS(SILC_OP_SOLVE), SILC_COMPLEX_OPS(SILC_OP_SOLVE), SILC_COMPLEX_OPS(SILC_OP_SOLVE), 0};

static const silc_plugin ss_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "suitesparse", SS_VERSION,
    (int)(sizeof ss_backends / sizeof ss_backends[0]), ss_backends,
    (int)(sizeof ss_options / sizeof ss_options[0]), ss_options,
    ss_set_threads, ss_shutdown, NULL, ss_complex_ops,
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
    if (silc_host_check(h, SILC_HOST_NEEDS(dense_new_uninit), errmsg) || !out) return 1;
    pthread_mutex_lock(&users_mutex);
    if (ss_users == 0) {
        ss_host = h;
        if (ss_start()) {
            pthread_mutex_unlock(&users_mutex);
            if (errmsg) *errmsg = "suitesparse: cholmod_l_start failed";
            return 1;
        }
        find_blas_threads();
    }
    ss_users++;
    pthread_mutex_unlock(&users_mutex);
    *out = &ss_plugin;
    return 0;
}
