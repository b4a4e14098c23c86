/*
 * lis_krylov_t.h -- CG (with COCG, its complex symmetric form) and
 * BiCGSTAB, written once over lis_field.h's names and included by
 * lis_krylov.c once real (lis_cg, lis_bicgstab: double or double-double)
 * and once complex (lis_cg_z, lis_cocg_z, lis_bicgstab_z).
 *
 * CG on a Hermitian A uses rho = r^H M^-1 r and p^H A p, real in exact
 * arithmetic, and needs p^H A p > 0 (its real part is tested: a breakdown
 * says A or M is not positive definite).  COCG runs the same recurrences
 * in the bilinear form x.' y, which a complex symmetric A (A = A.') makes
 * symmetric; it has no sign to test, only a zero (a breakdown) (van der
 * Vorst & Melissen 1990; Lis's cocg).  BiCGSTAB conjugates its shadow
 * residual (rho = r~^H r, omega = t^H s / t^H t), which makes it the
 * complex BiCGSTAB of the Templates book.
 */

/* ---- CG, COCG ---------------------------------------------------------------- */

static int FN(cg_run)(lis_ctx *c, lis_vec *x, int hermitian)
{
    lis_vec v[4], *r = &v[0], *z = &v[1], *p = &v[2], *q = &v[3];
    SC rho, rho1, pq, alpha;
    int st = LIS_MAXITER;
    (void)hermitian; /* the real instance has one form */
    if (lv_new_many(c, v, 4)) return LIS_NOMEM;
    lv_residual(c, x, r);
    rho = V_PSOLVE_DOT(c, r, z, hermitian);
    lv_copy(c, z, p);
    while (!lis_limit(c)) {
        pq = V_MATVEC_DOT(c, p, q, hermitian);
        if (hermitian && !(S_RE(pq) > 0))
            FAIL(pq, "p'Ap <= 0: A or the preconditioner is not positive definite");
        if (!hermitian && S_BAD(pq)) FAIL(pq, "p.'Ap = 0");
        alpha = S_DIV(rho, pq);
        STEP(V_AXPY2_NRM2(c, alpha, p, q, x, r));
        rho1 = V_PSOLVE_DOT(c, r, z, hermitian);
        FAIL_IF_ZERO(rho1, "r'M^-1 r = 0");
        V_XPAY(c, z, S_DIV(rho1, rho), p);
        rho = rho1;
    }
out:
    lv_free_many(v, 4);
    return st;
}

int FN(lis_cg)(lis_ctx *c, lis_vec *x)
{
    return FN(cg_run)(c, x, 1);
}

#ifdef LIS_COMPLEX
int lis_cocg_z(lis_ctx *c, lis_vec *x)
{
    return cg_run_z(c, x, 0);
}
#endif

/* ---- BiCGSTAB ------------------------------------------------------------------ */

int FN(lis_bicgstab)(lis_ctx *c, lis_vec *x)
{
    lis_vec v[8];
    lis_vec *r = &v[0], *rt = &v[1], *p = &v[2], *ph = &v[3], *w = &v[4], *s = &v[5],
            *sh = &v[6], *t = &v[7];
    SC rho, rho_old = S_ONE, alpha = S_ONE, omega = S_ONE, sig, tt, beta;
    dd snrm;
    int st = LIS_MAXITER, first = 1;
    if (lv_new_many(c, v, 8)) return LIS_NOMEM;
    lv_residual(c, x, r);
    initial_shadow(c, r, rt, t, 0);
    while (!lis_limit(c)) {
        rho = V_DOT(c, rt, r);
        FAIL_IF_ZERO(rho, "rho = (r~, r) = 0");
        if (first) {
            lv_copy(c, r, p);
            first = 0;
        } else {
            beta = S_MUL(S_DIV(rho, rho_old), S_DIV(alpha, omega));
            V_AXPY(c, S_NEG(omega), w, p);          /* p = r + beta (p - omega v) */
            V_XPAY(c, r, beta, p);
        }
        lv_psolve(c, p, ph);
        lv_matvec(c, ph, w);
        sig = V_DOT(c, rt, w);
        FAIL_IF_ZERO(sig, "(r~, A M^-1 p) = 0");
        alpha = S_DIV(rho, sig);
        V_WAXPBY(c, S_ONE, r, S_NEG(alpha), w, s);
        snrm = lv_nrm2(c, s);
        if (snrm.hi / c->den <= c->o->tol) {       /* converged half way */
            V_AXPY(c, alpha, ph, x);
            lv_copy(c, s, r);
            STEP(snrm);
        }
        lv_psolve(c, s, sh);
        lv_matvec(c, sh, t);
        tt = V_DOT(c, t, t);
        FAIL_IF_ZERO(tt, "(t, t) = 0");
        omega = S_DIV(V_DOT(c, t, s), tt);
        V_AXPY(c, alpha, ph, x);
        V_AXPY(c, omega, sh, x);
        V_WAXPBY(c, S_ONE, s, S_NEG(omega), t, r);
        rho_old = rho;
        STEP(lv_nrm2(c, r));
        if (S_IS_ZERO(omega)) FAIL(omega, "omega = 0");
    }
out:
    lv_free_many(v, 8);
    return st;
}
