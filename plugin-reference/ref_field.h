/*
 * ref_field.h -- the arithmetic a reference kernel template is instantiated
 * in: real (double) or complex (double complex, when REF_COMPLEX is defined).
 *
 * The direct solvers (ref_dense_t.h, ref_band_t.h, ref_sparse_t.h) are
 * written once over these macros and included twice, as CSparse builds
 * cs_di and cs_ci from one source: the control flow (pivot search, fill,
 * elimination order) is the same in both fields and only the arithmetic
 * differs, so one text serves both and a fix reaches both.  In the real
 * instantiation CONJ is the identity and MOD is fabs, so the real kernels
 * compile to what they were before the complex ones existed.
 *
 * Include this header, then the template, once per field; it undefines its
 * macros first, so it can be included again after REF_COMPLEX changes.
 */
#undef ENT
#undef FN
#undef CONJ
#undef MOD
#undef RE
#undef ENT_W
#undef INV_EST
#undef FIELD_NAME

#include <complex.h>
#include <math.h>

#ifdef REF_COMPLEX
#define ENT double complex          /* one entry */
#define FN(name) name##_z           /* the complex instance's name */
#define CONJ(x) conj(x)            /* conjugate (what "transpose" means: A^H) */
#define MOD(x) cabs(x)              /* modulus, for pivoting and norms */
#define RE(x) creal(x)
#define ENT_W 2                     /* doubles per entry */
#define INV_EST ref_inv_norm1_est_complex
#define FIELD_NAME "complex "
#else
#define ENT double
#define FN(name) name
#define CONJ(x) (x)
#define MOD(x) fabs(x)
#define RE(x) (x)
#define ENT_W 1
#define INV_EST ref_inv_norm1_est
#define FIELD_NAME ""
#endif
