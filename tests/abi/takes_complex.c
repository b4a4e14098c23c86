/* takes_complex.c -- an ABI 1.8 plugin listing SCALE in complex_ops: its
 * SCALE of a complex value gives (alpha + i alpha_imag) A + 2
 * (test_complex_core). */
#define FIX_NAME "takes_complex"
#define FIX_TAKES_COMPLEX 1
#define FIX_COMPLEX_OPS fix_complex_ops
#include "silc_plugin.h"
static const uint32_t fix_complex_ops[1] = {SILC_COMPLEX_OPS(SILC_OP_SCALE)};
#include "fixture.h"
