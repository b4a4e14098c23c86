/*
 * lis_krylov.c -- the short-recurrence Krylov solvers: CG, CR, BiCG, CGS,
 * BiCGSTAB, BiCGSTAB(l), GPBiCG, TFQMR, MINRES and IDR(s), and through the
 * shadow residual (initial_shadow) BiCR, CRS, BiCRSTAB and GPBiCR.
 *
 * Each is written once in the arithmetic of lis_space.c, so it runs in double or
 * double-double (-f quad); CG, COCG and BiCGSTAB are in lis_krylov_t.h,
 * included here once real and once complex.  Preconditioning follows the usual formulations:
 * CG, BiCG, CGS, BiCGSTAB, MINRES and IDR(s) as in the Templates book and the
 * original papers (the iterate x is updated directly); BiCGSTAB(l), GPBiCG
 * and TFQMR are run on the right-preconditioned operator A M^-1 with the
 * correction xi kept in the preconditioned space, and x = x0 + M^-1 xi is
 * formed when they stop.  In every method r is the (recursively updated) true
 * residual b - A x, except TFQMR and MINRES, which only have a bound or an
 * estimate; the driver (lis_style.c) recomputes b - A x when a method says
 * it converged and carries on if it did not.
 *
 * Breakdowns are divisions by an exact zero (rho, a curvature, a norm); a NaN
 * anywhere ends the run as LIS_NAN.
 *
 * The BiCR family.  BiCR's residuals r_k are orthogonal to A' K_k(A', s0)
 * where BiCG's are orthogonal to K_k(A', s0); since A' K_k(A', s0) =
 * K_k(A', A' s0), BiCR is BiCG started from the shadow residual A' s0, and
 * the product methods built on BiCR's residual polynomials (CRS, BiCRSTAB,
 * GPBiCR) are CGS, BiCGSTAB and GPBiCG started from it (Sogabe, Sugihara &
 * Zhang, JCAM 226, 2009, and the product-type papers that followed).  So
 * they are the same code with s0 = A' r0 instead of r0 (initial_shadow); in
 * exact arithmetic the iterates are those of the published recurrences,
 * whose rounding differs.  With a preconditioner the shadow is the
 * transpose of the operator the method runs on applied to r0: A' M^-T r0
 * for BiCR (BiCG's (A, M) form), M^-T A' r0 for the others (A M^-1).
 *
 * References: Barrett et al., Templates for the Solution of Linear Systems
 * (1994); Sleijpen & Fokkema, BiCGstab(l) (ETNA 1, 1993); Zhang, GPBi-CG (SISC
 * 18, 1997); Freund, TFQMR (SISC 14, 1993); Paige & Saunders, MINRES (SINUM
 * 12, 1975); van Gijzen & Sonneveld, IDR(s) with biorthogonalization (TOMS
 * 38, 2011, Algorithm 913).
 */
#include "lis.h"

#include <stdlib.h>
#include <string.h>

#include "lis_field.h" /* real: the methods below; the templates are included once per field */

/* Every solver loop is: work, then `STEP(norm)`, which leaves the loop with
 * the outcome when the method converged or produced NaN. */
#define STEP(nrm)                                  \
    do {                                           \
        st = lis_step(c, (nrm));                   \
        if (st >= 0) goto out;                     \
        st = LIS_MAXITER;                          \
    } while (0)
#define FAIL(v, why)                               \
    do {                                           \
        st = lis_fail(c, S_DD(v), (why));          \
        goto out;                                  \
    } while (0)
/* Breakdown: a quantity the method divides by is zero or NaN. */
#define FAIL_IF_ZERO(v, why)                       \
    do {                                           \
        if (S_BAD(v)) FAIL((v), (why));            \
    } while (0)

/* y = A M^-1 x (right preconditioning); t is scratch. */
static void apply_am(lis_ctx *c, const lis_vec *x, lis_vec *t, lis_vec *y)
{
    if (!c->pc) {
        lv_matvec(c, x, y);
        return;
    }
    lv_psolve(c, x, t);
    lv_matvec(c, t, y);
}

/* x += M^-1 xi: the end of a right-preconditioned run; t is scratch. */
static void finish_right(lis_ctx *c, lis_vec *x, const lis_vec *xi, lis_vec *t)
{
    lv_psolve(c, xi, t);
    lv_axpy(c, dd_d(1.0), t, x);
}

/* rt = the initial shadow residual: r, or for the BiCR family the transposed
 * operator applied to r (see the top of this file).  t is scratch;
 * left_form is 1 for BiCG's (A, M) form, 0 for the methods on A M^-1. */
static void initial_shadow(lis_ctx *c, const lis_vec *r, lis_vec *rt, lis_vec *t, int left_form)
{
    if (!lis_bicr_family(c->o->solver)) {
        lv_copy(c, r, rt);
    } else if (left_form) {
        lv_psolve_t(c, r, t);
        lv_matvec_t(c, t, rt);
    } else {
        lv_matvec_t(c, r, t);
        lv_psolve_t(c, t, rt);
    }
}

/* ---- CG, COCG and BiCGSTAB, real and complex (lis_krylov_t.h) ---------------- */

#define LIS_COMPLEX
#include "lis_field.h"
#include "lis_krylov_t.h"
#undef LIS_COMPLEX
#include "lis_field.h"
#include "lis_krylov_t.h"

/* ---- CR ------------------------------------------------------------------------ */

/* The conjugate residual method for symmetric A (and symmetric M): CG's
 * recurrences in the A-inner product, so that each iterate minimises the
 * residual's M^-1-norm over its Krylov space; A need not be definite. */
int lis_cr(lis_ctx *c, lis_vec *x)
{
    lis_vec v[6], *r = &v[0], *z = &v[1], *p = &v[2], *az = &v[3], *ap = &v[4], *q = &v[5];
    dd rho, rho1, apq, alpha;
    int st = LIS_MAXITER;
    if (lv_new_many(c, v, 6)) return LIS_NOMEM;
    lv_residual(c, x, r);
    lv_psolve(c, r, z);
    lv_copy(c, z, p);
    lv_matvec(c, z, az);
    lv_copy(c, az, ap);
    rho = lv_dot(c, z, az);
    while (!lis_limit(c)) {
        FAIL_IF_ZERO(rho, "(M^-1 r, A M^-1 r) = 0");
        lv_psolve(c, ap, q);
        apq = lv_dot(c, ap, q);
        FAIL_IF_ZERO(apq, "(A p, M^-1 A p) = 0");
        alpha = s_div(c, rho, apq);
        lv_axpy(c, alpha, p, x);
        lv_axpy(c, dd_neg(alpha), ap, r);
        STEP(lv_nrm2(c, r));
        lv_axpy(c, dd_neg(alpha), q, z);
        lv_matvec(c, z, az);
        rho1 = lv_dot(c, z, az);
        lv_xpay(c, z, s_div(c, rho1, rho), p);
        lv_xpay(c, az, s_div(c, rho1, rho), ap);
        rho = rho1;
    }
out:
    lv_free_many(v, 6);
    return st;
}

/* ---- BiCG -------------------------------------------------------------------- */

int lis_bicg(lis_ctx *c, lis_vec *x)
{
    lis_vec v[8];
    lis_vec *r = &v[0], *rt = &v[1], *z = &v[2], *zt = &v[3], *p = &v[4], *pt = &v[5],
            *q = &v[6], *qt = &v[7];
    dd rho, rho_old = dd_d(1), ptq, alpha, beta;
    int st = LIS_MAXITER, first = 1;
    if (lv_new_many(c, v, 8)) return LIS_NOMEM;
    lv_residual(c, x, r);
    initial_shadow(c, r, rt, zt, 1);
    while (!lis_limit(c)) {
        lv_psolve(c, r, z);
        lv_psolve_t(c, rt, zt);
        rho = lv_dot(c, z, rt);
        FAIL_IF_ZERO(rho, "rho = (M^-1 r, r~) = 0");
        if (first) {
            lv_copy(c, z, p);
            lv_copy(c, zt, pt);
            first = 0;
        } else {
            beta = s_div(c, rho, rho_old);
            lv_xpay(c, z, beta, p);
            lv_xpay(c, zt, beta, pt);
        }
        lv_matvec(c, p, q);
        lv_matvec_t(c, pt, qt);
        ptq = lv_dot(c, pt, q);
        FAIL_IF_ZERO(ptq, "(p~, A p) = 0");
        alpha = s_div(c, rho, ptq);
        lv_axpy(c, alpha, p, x);
        lv_axpy(c, dd_neg(alpha), q, r);
        lv_axpy(c, dd_neg(alpha), qt, rt);
        rho_old = rho;
        STEP(lv_nrm2(c, r));
    }
out:
    lv_free_many(v, 8);
    return st;
}

/* ---- CGS --------------------------------------------------------------------- */

int lis_cgs(lis_ctx *c, lis_vec *x)
{
    lis_vec v[8];
    lis_vec *r = &v[0], *rt = &v[1], *u = &v[2], *p = &v[3], *q = &v[4], *ph = &v[5],
            *vh = &v[6], *t = &v[7];
    dd rho, rho_old = dd_d(1), sig, alpha, beta;
    int st = LIS_MAXITER, first = 1;
    if (lv_new_many(c, v, 8)) return LIS_NOMEM;
    lv_residual(c, x, r);
    initial_shadow(c, r, rt, t, 0);
    while (!lis_limit(c)) {
        rho = lv_dot(c, rt, r);
        FAIL_IF_ZERO(rho, "rho = (r~, r) = 0");
        if (first) {
            lv_copy(c, r, u);
            lv_copy(c, u, p);
            first = 0;
        } else {
            beta = s_div(c, rho, rho_old);
            lv_waxpby(c, dd_d(1), r, beta, q, u);   /* u = r + beta q */
            lv_xpay(c, q, beta, p);                 /* p = u + beta (q + beta p) */
            lv_xpay(c, u, beta, p);
        }
        lv_psolve(c, p, ph);
        lv_matvec(c, ph, vh);
        sig = lv_dot(c, rt, vh);
        FAIL_IF_ZERO(sig, "(r~, A M^-1 p) = 0");
        alpha = s_div(c, rho, sig);
        lv_waxpby(c, dd_d(1), u, dd_neg(alpha), vh, q); /* q = u - alpha vh */
        lv_waxpby(c, dd_d(1), u, dd_d(1), q, t);        /* t = u + q */
        lv_psolve(c, t, ph);                            /* uh = M^-1 (u + q) */
        lv_axpy(c, alpha, ph, x);
        lv_matvec(c, ph, t);
        lv_axpy(c, dd_neg(alpha), t, r);
        rho_old = rho;
        STEP(lv_nrm2(c, r));
    }
out:
    lv_free_many(v, 8);
    return st;
}

/* ---- BiCGSTAB(l) ---------------------------------------------------------------- */

#define MAXL 20

int lis_bicgstabl(lis_ctx *c, lis_vec *x)
{
    int l = c->o->ell, nv = 2 * (l + 1) + 3, i, j, st = LIS_MAXITER;
    lis_vec *v = lis_host->calloc((size_t)nv, sizeof *v), *r, *u, *rt, *xi, *t;
    dd tau[MAXL + 1][MAXL + 1], sigma[MAXL + 1], gp[MAXL + 1], g[MAXL + 1], gpp[MAXL + 1];
    dd rho0 = dd_d(1), rho1, alpha = dd_d(0), omega = dd_d(1), beta, gam;
    if (!v) return LIS_NOMEM;
    if (lv_new_many(c, v, nv)) {
        lis_host->free(v);
        return LIS_NOMEM;
    }
    r = v, u = v + l + 1, rt = v + 2 * l + 2, xi = rt + 1, t = rt + 2;
    lv_residual(c, x, &r[0]);
    lv_copy(c, &r[0], rt);
    while (!lis_limit(c)) {
        rho0 = dd_neg(s_mul(c, omega, rho0));
        /* The BiCG part: l steps, each one counted as an iteration. */
        for (j = 0; j < l; j++) {
            rho1 = lv_dot(c, &r[j], rt);
            FAIL_IF_ZERO(rho1, "rho = (r_j, r~) = 0");
            beta = s_div(c, s_mul(c, alpha, rho1), rho0);
            rho0 = rho1;
            for (i = 0; i <= j; i++) lv_xpay(c, &r[i], dd_neg(beta), &u[i]);
            apply_am(c, &u[j], t, &u[j + 1]);
            gam = lv_dot(c, &u[j + 1], rt);
            FAIL_IF_ZERO(gam, "(A M^-1 u_j, r~) = 0");
            alpha = s_div(c, rho0, gam);
            for (i = 0; i <= j; i++) lv_axpy(c, dd_neg(alpha), &u[i + 1], &r[i]);
            apply_am(c, &r[j], t, &r[j + 1]);
            lv_axpy(c, alpha, &u[0], xi);
            STEP(lv_nrm2(c, &r[0]));
        }
        /* The minimal residual part: modified Gram-Schmidt on r_1..r_l. */
        for (j = 1; j <= l; j++) {
            for (i = 1; i < j; i++) {
                tau[i][j] = s_div(c, lv_dot(c, &r[j], &r[i]), sigma[i]);
                lv_axpy(c, dd_neg(tau[i][j]), &r[i], &r[j]);
            }
            sigma[j] = lv_dot(c, &r[j], &r[j]);
            FAIL_IF_ZERO(sigma[j], "(r_j, r_j) = 0 in the MR part");
            gp[j] = s_div(c, lv_dot(c, &r[0], &r[j]), sigma[j]);
        }
        g[l] = gp[l];
        omega = g[l];
        for (j = l - 1; j >= 1; j--) {
            dd s = gp[j];
            for (i = j + 1; i <= l; i++) s = s_sub(c, s, s_mul(c, tau[j][i], g[i]));
            g[j] = s;
        }
        for (j = 1; j < l; j++) {
            dd s = g[j + 1];
            for (i = j + 1; i < l; i++) s = s_add(c, s, s_mul(c, tau[j][i], g[i + 1]));
            gpp[j] = s;
        }
        lv_axpy(c, g[1], &r[0], xi);
        lv_axpy(c, dd_neg(gp[l]), &r[l], &r[0]);
        lv_axpy(c, dd_neg(g[l]), &u[l], &u[0]);
        for (j = 1; j < l; j++) {
            lv_axpy(c, dd_neg(g[j]), &u[j], &u[0]);
            lv_axpy(c, gpp[j], &r[j], xi);
            lv_axpy(c, dd_neg(gp[j]), &r[j], &r[0]);
        }
        st = lis_check(c, lv_nrm2(c, &r[0]));
        if (st >= 0) goto out;
        st = LIS_MAXITER;
        if (s_zero(omega)) FAIL(omega, "omega = 0");
    }
out:
    finish_right(c, x, xi, t);
    lv_free_many(v, nv);
    lis_host->free(v);
    return st;
}

/* ---- GPBiCG ------------------------------------------------------------------------ */

int lis_gpbicg(lis_ctx *c, lis_vec *x)
{
    lis_vec v[14];
    lis_vec *r = &v[0], *rt = &v[1], *p = &v[2], *ap = &v[3], *t = &v[4], *at = &v[5],
            *y = &v[6], *u = &v[7], *z = &v[8], *w = &v[9], *tp = &v[10], *xi = &v[11],
            *tmp = &v[12];
    dd alpha, beta = dd_d(0), zeta, eta, rtr, rtr_new, sig;
    int st = LIS_MAXITER, first = 1;
    if (lv_new_many(c, v, 13)) return LIS_NOMEM;
    lv_residual(c, x, r);
    initial_shadow(c, r, rt, tmp, 0);
    rtr = lv_dot(c, rt, r);
    while (!lis_limit(c)) {
        lv_axpy(c, dd_d(-1), u, p);                     /* p = r + beta (p - u) */
        lv_xpay(c, r, beta, p);
        apply_am(c, p, tmp, ap);
        sig = lv_dot(c, rt, ap);
        FAIL_IF_ZERO(sig, "(r~, A M^-1 p) = 0");
        if (s_zero(rtr)) FAIL(rtr, "(r~, r) = 0");
        alpha = s_div(c, rtr, sig);
        lv_waxpby(c, dd_d(1), tp, dd_d(-1), r, y);      /* y = t_prev - r - alpha w + alpha Ap */
        lv_axpy(c, dd_neg(alpha), w, y);
        lv_axpy(c, alpha, ap, y);
        lv_waxpby(c, dd_d(1), r, dd_neg(alpha), ap, t); /* t = r - alpha Ap */
        apply_am(c, t, tmp, at);
        if (first) {
            dd atat = lv_dot(c, at, at);
            FAIL_IF_ZERO(atat, "(At, At) = 0");
            zeta = s_div(c, lv_dot(c, at, t), atat);
            eta = dd_d(0);
        } else {
            dd atat = lv_dot(c, at, at), yy = lv_dot(c, y, y), yat = lv_dot(c, y, at);
            dd att = lv_dot(c, at, t), yt = lv_dot(c, y, t);
            dd den = s_sub(c, s_mul(c, atat, yy), s_mul(c, yat, yat));
            FAIL_IF_ZERO(den, "the 2x2 minimisation is singular");
            zeta = s_div(c, s_sub(c, s_mul(c, yy, att), s_mul(c, yt, yat)), den);
            eta = s_div(c, s_sub(c, s_mul(c, atat, yt), s_mul(c, yat, att)), den);
        }
        FAIL_IF_ZERO(zeta, "zeta = 0");
        /* u = zeta Ap + eta (t_prev - r + beta u) */
        lv_scale(c, beta, u);
        lv_axpy(c, dd_d(1), tp, u);
        lv_axpy(c, dd_d(-1), r, u);
        lv_scale(c, eta, u);
        lv_axpy(c, zeta, ap, u);
        /* z = zeta r + eta z - alpha u */
        lv_scale(c, eta, z);
        lv_axpy(c, zeta, r, z);
        lv_axpy(c, dd_neg(alpha), u, z);
        lv_axpy(c, alpha, p, xi);
        lv_axpy(c, dd_d(1), z, xi);
        lv_copy(c, t, r);                               /* r = t - eta y - zeta At */
        lv_axpy(c, dd_neg(eta), y, r);
        lv_axpy(c, dd_neg(zeta), at, r);
        STEP(lv_nrm2(c, r));
        rtr_new = lv_dot(c, rt, r);
        beta = s_mul(c, s_div(c, alpha, zeta), s_div(c, rtr_new, rtr));
        rtr = rtr_new;
        lv_waxpby(c, dd_d(1), at, beta, ap, w);         /* w = At + beta Ap */
        lv_copy(c, t, tp);
        first = 0;
    }
out:
    finish_right(c, x, xi, tmp);
    lv_free_many(v, 13);
    return st;
}

/* ---- TFQMR -------------------------------------------------------------------------- */

int lis_tfqmr(lis_ctx *c, lis_vec *x)
{
    lis_vec v[11];
    lis_vec *r = &v[0], *rt = &v[1], *w = &v[2], *y1 = &v[3], *y2 = &v[4], *u1 = &v[5],
            *u2 = &v[6], *vv = &v[7], *d = &v[8], *xi = &v[9], *tmp = &v[10];
    dd tau, theta = dd_d(0), eta = dd_d(0), rho, rho_new, sig, alpha, beta, cc;
    int st = LIS_MAXITER, j;
    int64_t m = 0;
    if (lv_new_many(c, v, 11)) return LIS_NOMEM;
    lv_residual(c, x, r);
    lv_copy(c, r, w);
    lv_copy(c, r, y1);
    lv_copy(c, r, rt);
    apply_am(c, y1, tmp, u1);
    lv_copy(c, u1, vv);
    tau = lv_nrm2(c, r);
    rho = lv_dot(c, rt, r);
    while (!lis_limit(c)) {
        sig = lv_dot(c, rt, vv);
        FAIL_IF_ZERO(sig, "(r~, v) = 0");
        alpha = s_div(c, rho, sig);
        for (j = 1; j <= 2; j++) {
            lis_vec *yj = j == 1 ? y1 : y2, *uj = j == 1 ? u1 : u2;
            if (j == 2) {
                lv_waxpby(c, dd_d(1), y1, dd_neg(alpha), vv, y2);
                apply_am(c, y2, tmp, u2);
            }
            lv_axpy(c, dd_neg(alpha), uj, w);
            lv_xpay(c, yj, s_div(c, s_mul(c, s_mul(c, theta, theta), eta), alpha), d);
            theta = s_div(c, lv_nrm2(c, w), tau);
            cc = s_div(c, dd_d(1), s_sqrt(c, s_add(c, dd_d(1), s_mul(c, theta, theta))));
            tau = s_mul(c, s_mul(c, tau, theta), cc);
            eta = s_mul(c, s_mul(c, cc, cc), alpha);
            lv_axpy(c, eta, d, xi);
            m++;
            /* Freund's bound ||r_m|| <= sqrt(m + 1) tau_m. */
            STEP(s_mul(c, tau, s_sqrt(c, dd_d((double)m + 1))));
            if (lis_limit(c)) goto out;
        }
        rho_new = lv_dot(c, rt, w);
        FAIL_IF_ZERO(rho_new, "rho = (r~, w) = 0");
        beta = s_div(c, rho_new, rho);
        rho = rho_new;
        lv_waxpby(c, dd_d(1), w, beta, y2, y1);
        apply_am(c, y1, tmp, u1);
        lv_xpay(c, u2, beta, vv);                        /* v = u1 + beta (u2 + beta v) */
        lv_xpay(c, u1, beta, vv);
    }
out:
    finish_right(c, x, xi, tmp);
    lv_free_many(v, 11);
    return st;
}

/* ---- MINRES --------------------------------------------------------------------------- */

/* Preconditioned MINRES (Paige-Saunders, as in Saunders' minres.m).  Its
 * residual estimate phibar is ||r|| in the M^-1 norm; scaled by the initial
 * ratio to the 2-norm it decides when to look at the true residual, and only
 * the true residual decides convergence. */
int lis_minres(lis_ctx *c, lis_vec *x)
{
    lis_vec v[8];
    lis_vec *r1 = &v[0], *r2 = &v[1], *y = &v[2], *vv = &v[3], *w = &v[4], *w1 = &v[5],
            *w2 = &v[6], *tmp = &v[7];
    dd beta1, beta, oldb = dd_d(0), alfa, dbar = dd_d(0), epsln = dd_d(0), oldeps, delta, gbar;
    dd phibar, phi, gamma, cs = dd_d(-1), sn = dd_d(0), ry;
    double scale, next_check = 1;
    int st = LIS_MAXITER;
    if (lv_new_many(c, v, 8)) return LIS_NOMEM;
    lv_residual(c, x, r1);
    lv_psolve(c, r1, y);
    ry = lv_dot(c, r1, y);
    if (!(ry.hi > 0)) FAIL(ry, "r'M^-1 r <= 0: the preconditioner is not positive definite");
    beta1 = s_sqrt(c, ry);
    scale = lv_nrm2(c, r1).hi / beta1.hi;
    beta = beta1;
    phibar = beta1;
    lv_copy(c, r1, r2);
    while (!lis_limit(c)) {
        double est;
        lv_copy(c, y, vv);
        lv_scale(c, s_div(c, dd_d(1), beta), vv);
        lv_matvec(c, vv, y);
        if (!s_zero(oldb)) lv_axpy(c, dd_neg(s_div(c, beta, oldb)), r1, y);
        alfa = lv_dot(c, vv, y);
        lv_axpy(c, dd_neg(s_div(c, alfa, beta)), r2, y);
        lv_copy(c, r2, r1);
        lv_copy(c, y, r2);
        lv_psolve(c, r2, y);
        oldb = beta;
        ry = lv_dot(c, r2, y);
        if (ry.hi < 0 || ry.hi != ry.hi) FAIL(ry, "r'M^-1 r < 0: the preconditioner is not positive definite");
        beta = s_sqrt(c, ry);
        oldeps = epsln;
        delta = s_add(c, s_mul(c, cs, dbar), s_mul(c, sn, alfa));
        gbar = s_sub(c, s_mul(c, sn, dbar), s_mul(c, cs, alfa));
        epsln = s_mul(c, sn, beta);
        dbar = dd_neg(s_mul(c, cs, beta));
        gamma = s_sqrt(c, s_add(c, s_mul(c, gbar, gbar), s_mul(c, beta, beta)));
        FAIL_IF_ZERO(gamma, "gamma = 0 (A is singular on the Krylov space)");
        cs = s_div(c, gbar, gamma);
        sn = s_div(c, beta, gamma);
        phi = s_mul(c, cs, phibar);
        phibar = s_mul(c, sn, phibar);
        /* w = (v - oldeps w1 - delta w2) / gamma, shifting w1 <- w2 <- w */
        lv_copy(c, w2, w1);
        lv_copy(c, w, w2);
        lv_copy(c, vv, w);
        lv_axpy(c, dd_neg(oldeps), w1, w);
        lv_axpy(c, dd_neg(delta), w2, w);
        lv_scale(c, s_div(c, dd_d(1), gamma), w);
        lv_axpy(c, phi, w, x);
        c->iter++;
        est = (phibar.hi < 0 ? -phibar.hi : phibar.hi) * scale;
        c->resid = est / c->den;
        if (c->resid != c->resid) {
            st = LIS_NAN;
            goto out;
        }
        if (c->o->print)
            lis_host->log(1, "lis-style %s: iteration %lld relative residual estimate %.6e (-print out)",
                          c->label, (long long)c->iter, c->resid);
        if (c->resid <= c->o->tol * next_check || s_zero(beta)) {
            double tr = lis_true_resid(c, x, tmp);
            if (tr <= c->o->tol) {
                c->resid = tr;
                st = LIS_CONVERGED;
                goto out;
            }
            next_check = c->resid / c->o->tol * 0.1; /* look again after 10x more */
            if (s_zero(beta)) {
                c->resid = tr;
                st = LIS_CONVERGED;                  /* Krylov space exhausted: driver decides */
                goto out;
            }
        }
    }
out:
    lv_free_many(v, 8);
    return st;
}

/* ---- IDR(s) ------------------------------------------------------------------------------ */

/* A fixed-seed generator for the shadow space P, so runs are reproducible. */
static double idr_random(uint64_t *state)
{
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    return (double)(*state >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

#define MAXS 64

int lis_idrs(lis_ctx *c, lis_vec *x)
{
    int s = c->o->idrs_s, nv = 3 * s + 3, i, j, k, st = LIS_MAXITER;
    lis_vec *v = lis_host->calloc((size_t)nv, sizeof *v), *P, *G, *U, *r, *vv, *t;
    dd *Ms = lis_host->calloc((size_t)s * (size_t)s, sizeof(dd)), f[MAXS], cf[MAXS], om = dd_d(1);
    uint64_t seed = 0x9E3779B97F4A7C15ULL;
    if (!v || !Ms || lv_new_many(c, v, nv)) {
        if (v) lis_host->free(v);
        if (Ms) lis_host->free(Ms);
        return LIS_NOMEM;
    }
    P = v, G = v + s, U = v + 2 * s, r = v + 3 * s, vv = r + 1, t = r + 2;
    /* P: s random vectors, orthonormalised. */
    for (i = 0; i < s; i++) {
        dd nrm;
        for (int64_t q = 0; q < c->n; q++) P[i].h[q] = idr_random(&seed);
        for (j = 0; j < i; j++) lv_axpy(c, dd_neg(lv_dot(c, &P[i], &P[j])), &P[j], &P[i]);
        nrm = lv_nrm2(c, &P[i]);
        if (s_zero(nrm)) FAIL(nrm, "random shadow space is degenerate");
        lv_scale(c, s_div(c, dd_d(1), nrm), &P[i]);
    }
    for (i = 0; i < s; i++) Ms[i * s + i] = dd_d(1);
    lv_residual(c, x, r);
    while (!lis_limit(c)) {
        dd tt, tr, nt, nr, rho;
        for (i = 0; i < s; i++) f[i] = lv_dot(c, &P[i], r);
        for (k = 0; k < s; k++) {
            dd beta;
            /* Solve the lower triangular Ms(k:s, k:s) c = f(k:s). */
            for (i = k; i < s; i++) {
                dd a = f[i];
                for (j = k; j < i; j++) a = s_sub(c, a, s_mul(c, Ms[i * s + j], cf[j]));
                cf[i] = s_div(c, a, Ms[i * s + i]);
            }
            lv_copy(c, r, vv);
            for (i = k; i < s; i++) lv_axpy(c, dd_neg(cf[i]), &G[i], vv);
            lv_psolve(c, vv, t);
            lv_scale(c, cf[k], &U[k]);
            for (i = k + 1; i < s; i++) lv_axpy(c, cf[i], &U[i], &U[k]);
            lv_axpy(c, om, t, &U[k]);
            lv_matvec(c, &U[k], &G[k]);
            /* Make G_k orthogonal to P_0..P_{k-1}. */
            for (i = 0; i < k; i++) {
                dd a = s_div(c, lv_dot(c, &P[i], &G[k]), Ms[i * s + i]);
                lv_axpy(c, dd_neg(a), &G[i], &G[k]);
                lv_axpy(c, dd_neg(a), &U[i], &U[k]);
            }
            for (i = k; i < s; i++) Ms[i * s + k] = lv_dot(c, &P[i], &G[k]);
            FAIL_IF_ZERO(Ms[k * s + k], "(P_k, G_k) = 0");
            beta = s_div(c, f[k], Ms[k * s + k]);
            lv_axpy(c, dd_neg(beta), &G[k], r);
            lv_axpy(c, beta, &U[k], x);
            STEP(lv_nrm2(c, r));
            if (lis_limit(c)) goto out;
            for (i = k + 1; i < s; i++) f[i] = s_sub(c, f[i], s_mul(c, beta, Ms[i * s + k]));
        }
        /* Dimension reduction: a minimal residual step, with the angle
         * safeguard (kappa = 0.7) of Sleijpen and van der Vorst. */
        lv_psolve(c, r, vv);
        lv_matvec(c, vv, t);
        tt = lv_dot(c, t, t);
        FAIL_IF_ZERO(tt, "(t, t) = 0");
        tr = lv_dot(c, t, r);
        nt = s_sqrt(c, tt);
        nr = lv_nrm2(c, r);
        om = s_div(c, tr, tt);
        rho = s_div(c, tr, s_mul(c, nt, nr));
        if (fabs(rho.hi) < 0.7) om = s_mul(c, om, dd_d(0.7 / fabs(rho.hi)));
        FAIL_IF_ZERO(om, "omega = 0");
        lv_axpy(c, dd_neg(om), t, r);
        lv_axpy(c, om, vv, x);
        STEP(lv_nrm2(c, r));
    }
out:
    lv_free_many(v, nv);
    lis_host->free(v);
    lis_host->free(Ms);
    return st;
}
