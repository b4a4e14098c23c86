/*
 * test_cow.c -- copy-on-write of `x += ...` (eval.c, update_in_place):
 * an unshared dense value is updated in place, anything else is copied, and
 * either way the numbers are bit for bit those of `x = x + ...`.
 *
 * White-box (the engine's store), because "in place" is only visible as the
 * same value object under the name:
 *   - x += 2*y, x -= 1, x *= 3, x /= 7 on an unshared x: the same object, a
 *     new id, entries equal to the plain expressions computed beside it;
 *   - x += y*0.37, x -= 1.5*y (scaled into x with no temporary), x += M*y
 *     (a matrix product: its result added in place): the same;
 *   - x += 2*x: through the temporary 2*x; x += 2*q with q of another
 *     length, x += 2*nope: refused, x untouched;
 *   - x = x + y, x = x - 0.5*y: the same updates, in place; x = y + x is not
 *     one (copied); x = x + q refused in the words of the expression;
 *   - x shared with w (w = x): x gets a new object, w keeps the old entries;
 *   - x += x (the right-hand side holds x too): copied, doubled;
 *   - a matrix with a factorization attached (D \ b ran): copied, and the
 *     next D \ b solves with the new D, not the old factors;
 *   - a result whose deferred backward error still holds it: copied;
 *   - `explain x += 1` changes nothing.
 */
#include "check.h"

#include <stdio.h>
#include <string.h>

#include "client.h"
#include "engine.h"
#include "store.h"

static silc_engine *E;
static char err[1024];

static int run(const char *text)
{
    int rc = api_exec(E, text, err, sizeof err);
    CHECK(rc == 0, "%s: %s", text, err);
    return rc;
}

static const silc_value *get(const char *name)
{
    const silc_value *v = api_lookup(E, name, err, sizeof err);
    CHECK(v != NULL, "lookup %s: %s", name, err);
    return v;
}

/* Entries of a and b identical bit for bit. */
static int same_entries(const char *a, const char *b)
{
    const silc_value *x = get(a), *y = get(b);
    return x && y && x->m == y->m && x->n == y->n && x->format == SILC_FMT_DENSE &&
           y->format == SILC_FMT_DENSE && memcmp(x->val, y->val, (size_t)(x->m * x->n) * sizeof(double)) == 0;
}

static void check_in_place(const char *stmt, const char *expected)
{
    const silc_value *before = get("x");
    uint64_t id = before ? before->id : 0;
    if (run(stmt)) return;
    CHECK(get("x") == before, "%s: x was copied, not updated in place", stmt);
    CHECK(get("x")->id != id, "%s: x kept its id after changing", stmt);
    CHECK(same_entries("x", expected), "%s: entries differ from %s", stmt, expected);
}

static void check_copied(const char *stmt, const char *expected)
{
    const silc_value *before = get("x");
    if (run(stmt)) return;
    CHECK(get("x") != before, "%s: x was updated in place though shared", stmt);
    CHECK(same_entries("x", expected), "%s: entries differ from %s", stmt, expected);
}

int main(void)
{
    const silc_value *w_before;
    if (eng_create(&E, "/dev/null", err, sizeof err)) {
        CHECK(0, "eng_create: %s", err);
        return check_done();
    }
    run("x = rand(1000, 1); y = rand(1000, 1)");
    run("e = x + 2 * y");
    check_in_place("x += 2 * y", "e");
    run("e = x - 1");
    check_in_place("x -= 1", "e");
    run("e = x * 3");
    check_in_place("x *= 3", "e");
    run("e = x / 7");
    check_in_place("x /= 7", "e");
    run("e = x - y");
    check_in_place("x -= y", "e");
    run("e = x + y * 0.37");
    check_in_place("x += y * 0.37", "e");
    run("e = x - 1.5 * y");
    check_in_place("x -= 1.5 * y", "e");
    run("M = 2 * eye(1000); e = x + M * y");
    check_in_place("x += M * y", "e");
    /* y is x: not scaled into x over itself, but 2 * x is a temporary that
     * nothing else holds, added in place. */
    run("e = x + 2 * x");
    check_in_place("x += 2 * x", "e");
    {
        const silc_value *before = get("x");
        run("f = x * 1; q = ones(999, 1)");
        CHECK(api_exec(E, "x += 2 * q", err, sizeof err) != 0 && strstr(err, "same shape"),
              "x += 2 * q (999 entries): %s", err);
        CHECK(api_exec(E, "x += 2 * nope", err, sizeof err) != 0 && strstr(err, "nope"),
              "x += 2 * nope: %s", err);
        CHECK(get("x") == before && same_entries("x", "f"), "a refused x += 2 * ... changed x");
    }

    /* x = x + e is x += e. */
    run("e = x + y");
    check_in_place("x = x + y", "e");
    run("e = x - 0.5 * y");
    check_in_place("x = x - 0.5 * y", "e");
    run("e = y + x");
    check_copied("x = y + x", "e");
    {
        const silc_value *before = get("x");
        run("f = x * 1");
        CHECK(api_exec(E, "x = x + q", err, sizeof err) != 0 &&
                  strstr(err, "'+' needs operands of the same shape or a scalar: 'x' is 1000x1, 'q' is 999x1"),
              "x = x + q: %s", err);
        CHECK(get("x") == before && same_entries("x", "f"), "a refused x = x + q changed x");
    }

    /* Shared: w sees none of it. */
    run("w = x; e = x + 1; f = x * 1"); /* f: a copy of the entries */
    w_before = get("w");
    check_copied("x += 1", "e");
    CHECK(get("w") == w_before && same_entries("w", "f"), "w changed with x");
    run("w = x; e = x - 2 * y; f = x * 1");
    w_before = get("w");
    check_copied("x = x - 2 * y", "e");
    CHECK(get("w") == w_before && same_entries("w", "f"), "w changed with x = x - 2 * y");

    /* The right-hand side is x itself. */
    run("e = x + x");
    check_copied("x += x", "e");

    /* A factorization hangs on D: D += 1 must not leave D \ b using it. */
    run("D = dense(eye(4) * 3 + ones(4, 4)); d = D \\ ones(4, 1)");
    {
        const silc_value *D = get("D");
        run("D += 1; d2 = D \\ ones(4, 1)");
        CHECK(get("D") != D, "D with attached factors was updated in place");
        run("F = dense(eye(4) * 3 + ones(4, 4)) + 1; d3 = F \\ ones(4, 1)");
        CHECK(same_entries("d2", "d3"), "D \\ b after D += 1 used the old factors");
    }

    /* A reused solve's deferred backward error holds its result. */
    run("x = D \\ ones(4, 1); x = D \\ ones(4, 1); e = x + 1");
    check_copied("x += 1", "e");

    /* explain runs nothing. */
    run("f = x * 1");
    if (run("explain x += 1") == 0) CHECK(same_entries("x", "f"), "explain x += 1 changed x");

    eng_destroy(&E);
    return check_done();
}
