/* good.c -- a correct plugin named "good": SCALE computes alpha*A + 1. */
#define FIX_NAME "good"
#include "fixture.h"
