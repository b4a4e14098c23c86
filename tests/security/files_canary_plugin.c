/*
 * files_canary_plugin.c -- foreign code for the attack suite
 * (tests/security/files.cmake): a library named like a plugin
 * (libsilc_plugin_x.so) whose constructor runs the moment anything dlopens
 * it, before SILC could look at its plugin table, and leaves a marker file
 * (the path in SILC_CANARY_MARKER).  The test asserts that no silcd session
 * made it run, and, as its control, that an embedded program that sets
 * core.plugin_path to its folder does.
 */
#include <stdio.h>
#include <stdlib.h>

__attribute__((constructor)) static void canary_ran(void)
{
    const char *marker = getenv("SILC_CANARY_MARKER");
    FILE *f;
    if (!marker || !*marker || !(f = fopen(marker, "w"))) return;
    fputs("foreign code ran here\n", f);
    fclose(f);
}
