/*
 * lis_gmres_t.h -- GMRES(m) and FGMRES(m) (Arnoldi with modified
 * Gram-Schmidt on A M^-1, Givens rotations on the Hessenberg matrix),
 * written once over lis_field.h's names and included by lis_gmres.c once
 * real (lis_gmres, lis_fgmres) and once complex (lis_gmres_z,
 * lis_fgmres_z).  In complex arithmetic the Gram-Schmidt coefficients are
 * V_i^H w, and each rotation [conj(cs) sn; -sn cs] has a real sn (the
 * subdiagonal entry it annihilates is a norm), zlartg's convention for a
 * real second entry; the residual norm is |g_{j+1}|.
 */

static int FN(arnoldi)(lis_ctx *c, lis_vec *x, int flexible)
{
    int m = c->o->restart, nv = (m + 1) + (flexible ? m : 1) + 1, i, j, k, st = LIS_MAXITER;
    lis_vec *v = lis_host->calloc((size_t)nv, sizeof *v), *V, *Z, *w;
    SC *H = lis_host->calloc((size_t)(m + 1) * (size_t)m, sizeof(SC));
    SC *cs = lis_host->calloc((size_t)m, sizeof(SC)), *sn = lis_host->calloc((size_t)m, sizeof(SC));
    SC *g = lis_host->calloc((size_t)m + 1, sizeof(SC)), *y = lis_host->calloc((size_t)m, sizeof(SC));
#define Hij(i, j) H[(size_t)(j) * (size_t)(m + 1) + (size_t)(i)]
    if (!v || !H || !cs || !sn || !g || !y || lv_new_many(c, v, nv)) {
        st = LIS_NOMEM;
        goto free_all;
    }
    V = v, Z = v + m + 1, w = v + nv - 1;
    while (!lis_limit(c)) {
        dd beta;
        int happy = 0;
        lv_residual(c, x, &V[0]);
        beta = lv_nrm2(c, &V[0]);
        if (beta.hi != beta.hi) {
            st = lis_fail(c, beta, "");
            goto done;
        }
        if (beta.hi / c->den <= c->o->tol) {
            c->resid = beta.hi / c->den;
            st = LIS_CONVERGED;
            goto done;
        }
        V_SCALE(c, S_DIV(S_ONE, S_FROM_DD(beta)), &V[0]);
        g[0] = S_FROM_DD(beta);
        for (i = 1; i <= m; i++) g[i] = S_ZERO;
        for (j = 0; j < m && !lis_limit(c); j++) {
            lis_vec *z = flexible ? &Z[j] : &Z[0];
            dd h, r;
            lv_psolve(c, &V[j], z);
            lv_matvec(c, z, w);
            for (i = 0; i <= j; i++) {
                Hij(i, j) = V_DOT(c, &V[i], w); /* V_i^H w */
                V_AXPY(c, S_NEG(Hij(i, j)), &V[i], w);
            }
            h = lv_nrm2(c, w);
            Hij(j + 1, j) = S_FROM_DD(h);
            if (!s_zero(h)) {
                lv_copy(c, w, &V[j + 1]);
                V_SCALE(c, S_DIV(S_ONE, S_FROM_DD(h)), &V[j + 1]);
            }
            /* Apply the earlier rotations to the new column, then make its own:
             * [conj(cs) sn; -sn cs] with sn real (h is a norm), which is
             * unitary as |cs|^2 + sn^2 = 1, and zeroes h under Hij(j, j). */
            for (i = 0; i < j; i++) {
                SC a = Hij(i, j), b = Hij(i + 1, j);
                Hij(i, j) = S_ADD(S_MUL(S_CONJ(cs[i]), a), S_MUL(sn[i], b));
                Hij(i + 1, j) = S_SUB(S_MUL(cs[i], b), S_MUL(sn[i], a));
            }
            r = s_sqrt(c, s_add(c, S_ABS2(Hij(j, j)), s_mul(c, h, h)));
            if (s_zero(r) || r.hi != r.hi) {
                st = lis_fail(c, r, "the Hessenberg matrix is singular");
                goto done; /* nothing of this cycle can be used */
            }
            cs[j] = S_DIV(Hij(j, j), S_FROM_DD(r));
            sn[j] = S_DIV(S_FROM_DD(h), S_FROM_DD(r));
            Hij(j, j) = S_FROM_DD(r);
            Hij(j + 1, j) = S_ZERO;
            g[j + 1] = S_NEG(S_MUL(sn[j], g[j]));
            g[j] = S_MUL(S_CONJ(cs[j]), g[j]);
            st = lis_step(c, dd_d(S_MOD(g[j + 1])));
            if (st == LIS_NAN) goto done;
            happy = s_zero(h); /* the Krylov space is invariant: the solution is in it */
            if (st == LIS_CONVERGED || happy) {
                j++;
                break;
            }
            st = LIS_MAXITER;
        }
        /* x += M^-1 V y (GMRES) or Z y (FGMRES), y from the triangular H y = g. */
        k = j;
        for (i = k - 1; i >= 0; i--) {
            SC s = g[i];
            for (int q = i + 1; q < k; q++) s = S_SUB(s, S_MUL(Hij(i, q), y[q]));
            y[i] = S_DIV(s, Hij(i, i));
        }
        if (flexible) {
            for (i = 0; i < k; i++) V_AXPY(c, y[i], &Z[i], x);
        } else {
            lv_zero(c, w);
            for (i = 0; i < k; i++) V_AXPY(c, y[i], &V[i], w);
            lv_psolve(c, w, &Z[0]);
            V_AXPY(c, S_ONE, &Z[0], x);
        }
        if (st == LIS_CONVERGED || happy) {
            st = LIS_CONVERGED;
            goto done;
        }
    }
done:
    lv_free_many(v, nv);
free_all:
    if (v) lis_host->free(v);
    if (H) lis_host->free(H);
    if (cs) lis_host->free(cs);
    if (sn) lis_host->free(sn);
    if (g) lis_host->free(g);
    if (y) lis_host->free(y);
#undef Hij
    return st;
}

int FN(lis_gmres)(lis_ctx *c, lis_vec *x)
{
    return FN(arnoldi)(c, x, 0);
}

int FN(lis_fgmres)(lis_ctx *c, lis_vec *x)
{
    return FN(arnoldi)(c, x, 1);
}

