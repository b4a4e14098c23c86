/*
 * ref_matmul.c -- the reference plugin's matrix product.
 *
 * Sparse times sparse (CSR or band operands) is Gustavson's row-by-row
 * product with a dense accumulator and a marker array, giving CSR with sorted
 * columns; any dense operand gives a dense result.  Dense kernels run in
 * column order (j, k, i) so the innermost loop walks contiguous memory; a band
 * operand is read as CSR, which costs one cheap conversion.  The kernels
 * live in ref_matmul_t.h, instantiated for real and complex entries
 * (ref_field.h); the host never mixes fields in one call.
 */
#include "ref.h"

#include <string.h>

#undef REF_COMPLEX
#include "ref_field.h"
#include "ref_matmul_t.h"

#define REF_COMPLEX
#include "ref_field.h"
#include "ref_matmul_t.h"
#undef REF_COMPLEX

int ref_op_matmul(silc_call *call)
{
    silc_view a, b;
    ref_host->view(call->in[0], &a);
    ref_host->view(call->in[1], &b);
    if (a.n != b.m)
        return ref_host->error(call, SILC_EARG, "matmul: inner dimensions differ (%lldx%lld * %lldx%lld)",
                               (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
    int w = ref_width(call->in[0]);
    if (ref_width(call->in[1]) != w)
        return ref_host->error(call, SILC_EARG, "matmul: one operand is complex and the other real "
                                                "(the host promotes the real one first)");
    return w == 2 ? matmul_z(call, &a, &b) : matmul(call, &a, &b);
}
