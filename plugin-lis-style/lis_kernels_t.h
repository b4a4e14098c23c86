/*
 * lis_kernels_t.h -- the field-dependent kernels of lis_kernels.c (SpMV,
 * residual, inner product, the BLAS-1 updates and the fused CG passes),
 * written once and included twice by lis_kernels.c: once real (ENT double,
 * the lk_* names) and once complex (LK_COMPLEX: ENT double complex, the
 * lk_*_z names, values interleaved re, im as the plugin ABI stores them).
 * The real instance is the text the kernels had before complex values, so
 * it compiles to the same loops (CONJ is the identity there).
 *
 * Inner products conjugate their first operand (x^H y, what CG, BiCGSTAB
 * and Arnoldi need); the complex instance also has the unconjugated x.' y
 * (lk_dotu_z), which COCG runs on.  A fused kernel takes `conjugate` to
 * choose between them (the real instance ignores it).
 */
#undef ENT
#undef FN
#undef CONJ
#undef CONJ_IF
#ifdef LK_COMPLEX
#define ENT double complex
#define FN(name) name##_z
#define CONJ(x) conj(x)
#define CONJ_IF(flag, x) ((flag) ? conj(x) : (x))
#else
#define ENT double
#define FN(name) name
#define CONJ(x) (x)
#define CONJ_IF(flag, x) (x)
#endif

void FN(lk_spmv)(const lk_csr *A, const ENT *x, ENT *y)
{
    const int64_t *rp = A->rp, *ci = A->ci;
    const ENT *v = (const ENT *)A->v;
    int64_t i, m = A->m;
    LK_FOR(m, i, ENT s = 0.0; for (int64_t k = rp[i]; k < rp[i + 1]; k++) s += v[k] * x[ci[k]];
           y[i] = s);
}

void FN(lk_residual)(const lk_csr *A, const ENT *b, const ENT *x, ENT *r)
{
    const int64_t *rp = A->rp, *ci = A->ci;
    const ENT *v = (const ENT *)A->v;
    int64_t i, m = A->m;
    LK_FOR(m, i, ENT s = b[i]; for (int64_t k = rp[i]; k < rp[i + 1]; k++) s -= v[k] * x[ci[k]];
           r[i] = s);
}

ENT FN(lk_dot)(int64_t n, const ENT *x, const ENT *y)
{
    ENT s = 0.0;
    int64_t i;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", s += CONJ(x[i]) * y[i]);
    return s;
}

void FN(lk_scale)(int64_t n, ENT a, ENT *x)
{
    int64_t i;
    LK_FOR(n, i, x[i] *= a);
}

void FN(lk_axpy)(int64_t n, ENT a, const ENT *x, ENT *y)
{
    int64_t i;
    LK_FOR(n, i, y[i] += a * x[i]);
}

void FN(lk_xpay)(int64_t n, const ENT *x, ENT a, ENT *y)
{
    int64_t i;
    LK_FOR(n, i, y[i] = x[i] + a * y[i]);
}

void FN(lk_waxpby)(int64_t n, ENT a, const ENT *x, ENT b, const ENT *y, ENT *w)
{
    int64_t i;
    LK_FOR(n, i, w[i] = a * x[i] + b * y[i]);
}

/* The fused kernels.  A CG iteration with Jacobi made of the single
 * kernels above sweeps its vectors eight times; these make it four, which
 * is what a hand-written CG does (docs/cloth.md measured the difference on
 * the cloth: 1.3x).  y = A x; x^H y (x.' y when not conjugate). */
#ifdef LK_COMPLEX
ENT FN(lk_spmv_dot)(const lk_csr *A, const ENT *x, ENT *y, int conjugate)
#else
ENT FN(lk_spmv_dot)(const lk_csr *A, const ENT *x, ENT *y)
#endif
{
    const int64_t *rp = A->rp, *ci = A->ci;
    const ENT *v = (const ENT *)A->v;
    int64_t i, m = A->m;
    ENT d = 0.0;
    LK_REDUCE(m, i, "omp parallel for schedule(static) reduction(+ : d)", ENT s = 0.0;
              for (int64_t k = rp[i]; k < rp[i + 1]; k++) s += v[k] * x[ci[k]];
              y[i] = s; d += CONJ_IF(conjugate, x[i]) * s);
    return d;
}

/* x += a p, r -= a q; sum |r_i|^2 (a real number in both fields). */
double FN(lk_axpy2_sumsq)(int64_t n, ENT a, const ENT *p, const ENT *q, ENT *x, ENT *r)
{
    double s = 0.0;
    int64_t i;
#ifdef LK_COMPLEX
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", x[i] += a * p[i];
              r[i] -= a * q[i]; s += creal(r[i]) * creal(r[i]) + cimag(r[i]) * cimag(r[i]));
#else
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", x[i] += a * p[i];
              r[i] -= a * q[i]; s += r[i] * r[i]);
#endif
    return s;
}

/* z = d.*r; r^H z (r.' z when not conjugate). */
#ifdef LK_COMPLEX
ENT FN(lk_mul_dot)(int64_t n, const ENT *d, const ENT *r, ENT *z, int conjugate)
#else
ENT FN(lk_mul_dot)(int64_t n, const ENT *d, const ENT *r, ENT *z)
#endif
{
    ENT s = 0.0;
    int64_t i;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", z[i] = d[i] * r[i];
              s += CONJ_IF(conjugate, r[i]) * z[i]);
    return s;
}

#ifdef LK_COMPLEX
/* x.' y: the unconjugated product of complex symmetric methods (COCG). */
ENT lk_dotu_z(int64_t n, const ENT *x, const ENT *y)
{
    ENT s = 0.0;
    int64_t i;
    LK_REDUCE(n, i, "omp parallel for schedule(static) reduction(+ : s)", s += x[i] * y[i]);
    return s;
}
#endif
