/*
 * lis_field.h -- the arithmetic a solver template (lis_krylov_t.h,
 * lis_gmres_t.h) and the preconditioner template (lis_precond_t.h) are
 * instantiated in: real, or complex when LIS_COMPLEX is defined.
 *
 * The real instance is what the solvers always were: scalars are
 * double-double numbers rounded to double unless -f quad (lis.h's s_*), the
 * vectors lis_space.c's lv_*.  The complex instance has double complex
 * scalars and the lvz_* vector operations (complex entries interleaved in
 * a lis_vec's h; no double-double: -f quad is refused for complex values).
 * Norms are real in both fields and keep the dd type, so lis_step and
 * lis_fail serve both.  A method is written once over these names and
 * included once per field, as plugin-reference's ref_field.h does for the
 * direct kernels: a fix reaches both fields.
 *
 * Inner products conjugate their first operand (V_DOT(x, y) = x^H y).
 * The fused CG passes take `hermitian`: 1 for CG (x^H y), 0 for COCG, which
 * runs CG's recurrences in the bilinear form x.' y of a complex symmetric
 * matrix (van der Vorst & Melissen, IEEE Trans. Magn. 26, 1990); the real
 * instance ignores it.  Include this header, then the template, once per
 * field; it undefines its names first.
 */
#undef SC
#undef FN
#undef S_ADD
#undef S_SUB
#undef S_MUL
#undef S_DIV
#undef S_NEG
#undef S_CONJ
#undef S_ONE
#undef S_ZERO
#undef S_FROM_DD
#undef S_RE
#undef S_MOD
#undef S_ABS2
#undef S_IS_ZERO
#undef S_BAD
#undef S_DD
#undef V_DOT
#undef V_AXPY
#undef V_XPAY
#undef V_WAXPBY
#undef V_SCALE
#undef V_MATVEC_DOT
#undef V_AXPY2_NRM2
#undef V_PSOLVE_DOT
#undef ENT
#undef MOD
#undef RE

#include <complex.h>
#include <math.h>

#ifdef LIS_COMPLEX
#define SC double complex
#define FN(name) name##_z
#define S_ADD(a, b) ((a) + (b))
#define S_SUB(a, b) ((a) - (b))
#define S_MUL(a, b) ((a) * (b))
#define S_DIV(a, b) ((a) / (b))
#define S_NEG(a) (-(a))
#define S_CONJ(a) conj(a)
#define S_ONE ((double complex)1)
#define S_ZERO ((double complex)0)
#define S_FROM_DD(d) ((double complex)(d).hi)
#define S_RE(a) creal(a)
#define S_MOD(a) cabs(a)
#define S_ABS2(a) dd_d(creal(a) * creal(a) + cimag(a) * cimag(a))
#define S_IS_ZERO(a) ((a) == 0)
#define S_BAD(a) ((a) == 0 || isnan(creal(a)) || isnan(cimag(a)))
#define S_DD(a) dd_d(cabs(a))
#define V_DOT(c, x, y) lvz_dot((c), (x), (y))
#define V_AXPY lvz_axpy
#define V_XPAY lvz_xpay
#define V_WAXPBY lvz_waxpby
#define V_SCALE lvz_scale
#define V_MATVEC_DOT(c, x, y, herm) lvz_matvec_dot((c), (x), (y), (herm))
#define V_AXPY2_NRM2 lvz_axpy2_nrm2
#define V_PSOLVE_DOT(c, r, z, herm) lvz_psolve_dot((c), (r), (z), (herm))
/* the preconditioner template's entries */
#define ENT double complex
#define MOD(x) cabs(x)
#define RE(x) creal(x)
#else
#define SC dd
#define FN(name) name
#define S_ADD(a, b) s_add(c, (a), (b))
#define S_SUB(a, b) s_sub(c, (a), (b))
#define S_MUL(a, b) s_mul(c, (a), (b))
#define S_DIV(a, b) s_div(c, (a), (b))
#define S_NEG(a) dd_neg(a)
#define S_CONJ(a) (a)
#define S_ONE dd_d(1)
#define S_ZERO dd_d(0)
#define S_FROM_DD(d) (d)
#define S_RE(a) ((a).hi)
#define S_MOD(a) fabs((a).hi)
#define S_ABS2(a) s_mul(c, (a), (a))
#define S_IS_ZERO(a) s_zero(a)
#define S_BAD(a) (s_zero(a) || (a).hi != (a).hi)
#define S_DD(a) (a)
#define V_DOT(c, x, y) lv_dot((c), (x), (y))
#define V_AXPY lv_axpy
#define V_XPAY lv_xpay
#define V_WAXPBY lv_waxpby
#define V_SCALE lv_scale
#define V_MATVEC_DOT(c, x, y, herm) lv_matvec_dot((c), (x), (y))
#define V_AXPY2_NRM2 lv_axpy2_nrm2
#define V_PSOLVE_DOT(c, r, z, herm) lv_psolve_dot((c), (r), (z))
#define ENT double
#define MOD(x) fabs(x)
#define RE(x) (x)
#endif
