/*
 * test_scene.c -- checks scene.c, the reader of the cloth example's scene
 * files: good scenes give the values written (or the documented defaults),
 * and every kind of mistake gives its exact message, since those messages
 * are what a user sees.  Then it reads the real scenes from the directory
 * named by argv[1], and files too large or with NUL bytes from a temporary
 * directory.  The last line printed is "N passed, M failed"; the exit status
 * is non-zero if anything failed.
 *
 *   test_scene examples/cloth/scenes
 */
#define _POSIX_C_SOURCE 200809L /* mkdtemp, rmdir */

#include "cloth.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int passed, failed;

static bool check(bool ok, int line, const char *what)
{
    if (ok) {
        passed++;
    } else {
        failed++;
        printf("FAIL (test_scene.c:%d): %s\n", line, what);
    }
    return ok;
}
#define CHECK(cond) check((cond), __LINE__, #cond)

/* The minimum a scene needs: the three required keys. */
#define BASE "nx = 4\nny = 3\naccuracy = 0.01\n"

static bool parse_ok(int line, const char *text, cloth_scene *s)
{
    char err[256];
    int rc = scene_parse(text, "t", s, err, sizeof err);
    if (rc != 0)
        printf("FAIL (test_scene.c:%d): unexpected error: %s\n", line, err);
    return check(rc == 0, line, "scene parses");
}
#define PARSE_OK(text, s) parse_ok(__LINE__, (text), (s))

static void expect_error(int line, const char *text, const char *expected)
{
    cloth_scene s;
    char err[256];
    int rc = scene_parse(text, "t", &s, err, sizeof err);
    if (rc != -1 || strcmp(err, expected) != 0)
        printf("FAIL (test_scene.c:%d): expected -1 and \"%s\", got %d and \"%s\"\n", line, expected, rc,
               rc == -1 ? err : "");
    check(rc == -1 && strcmp(err, expected) == 0, line, expected);
}
#define EXPECT_ERROR(text, expected) expect_error(__LINE__, (text), (expected))

/* Values that parse but cannot be simulated: the message names the key (and
 * its line) and the criterion. */
static void expect_unsimulable(int line, const char *text, const char *start, const char *criterion)
{
    cloth_scene s;
    char err[1024];
    int rc = scene_parse(text, "t", &s, err, sizeof err);
    bool ok = rc == -1 && strncmp(err, start, strlen(start)) == 0 && strstr(err, criterion) != NULL;
    if (!ok) printf("FAIL (test_scene.c:%d): expected \"%s...%s...\", got %d and \"%s\"\n", line, start, criterion, rc, rc ? err : "");
    check(ok, line, start);
}

static void test_unsimulable(void)
{
    cloth_scene s;
    expect_unsimulable(__LINE__, BASE "mass = 1e-300\n", "t:4: mass: 1e-300 kg over 1 m^2 is 1e-300 kg/m^2",
                       "below the floor of 1e-6 kg/m^2");
    expect_unsimulable(__LINE__, BASE "dt = 1e9\n", "t:4: dt: in one step of 1e+09 s free fall alone covers",
                       "more than the cloth's size 1 m");
    expect_unsimulable(__LINE__, BASE "k_struct = 1e18\n", "t: the system's condition bound", "exceeds the accuracy");
    EXPECT_ERROR(BASE "max_stretch = 1\n", "t:4: max_stretch: expected a number > 1, got '1'");
    /* at the edges: 1e-6 kg/m^2 and free fall of exactly the size pass;
     * without gravity dt meets only the condition bound */
    check(PARSE_OK(BASE "mass = 1e-6\n", &s) && s.max_stretch == 1.5, __LINE__, "1e-6 kg/m^2 passes");
    PARSE_OK(BASE "gravity = 0 0 -2\ndt = 1\n", &s);
    PARSE_OK(BASE "gravity = 0 0 0\ndt = 100\n", &s);
}

static void test_defaults(void)
{
    cloth_scene s;
    if (!PARSE_OK(BASE, &s))
        return;
    CHECK(strcmp(s.name, "t") == 0); /* scene_parse names the scene after its origin */
    CHECK(s.nx == 4 && s.ny == 3 && s.accuracy == 0.01);
    CHECK(s.width == 1 && s.height == 1 && s.mass == 1);
    CHECK(s.k_struct == 1000 && s.k_shear == 100 && s.k_bend == 10 && s.damping == 0.1);
    CHECK(s.gravity[0] == 0 && s.gravity[1] == 0 && s.gravity[2] == -9.81);
    CHECK(s.dt == 0.005 && s.steps == 100 && s.frame_every == 0);
    CHECK(s.npins == 0 && s.tilt == 0 && s.obstacle == OBSTACLE_NONE);
}

/* Every key, with comments, tabs, CRLF line ends and no final newline. */
static void test_every_key(void)
{
    cloth_scene s;
    if (!PARSE_OK("# a comment line\r\n"
                  "\r\n"
                  "   \t  \n"
                  "  name=full_1.b-x  # a trailing comment\r\n"
                  "\tnx\t=\t5\r\n"
                  "ny = 2\n"
                  "width = 2.5\nheight=0.5\nmass = 3e-1\n"
                  "k_struct = 1500\nk_shear = 0\nk_bend = 0\ndamping = 0\n"
                  "gravity = 0   -1.5\t9.81\n"
                  "dt = 1e-3\nsteps = 7\nframe_every = 3\ntilt = -90\n"
                  "obstacle = floor -0.25\naccuracy = 0.5\n"
                  "pin = 4 1\npin=0 0",
                  &s))
        return;
    CHECK(strcmp(s.name, "full_1.b-x") == 0);
    CHECK(s.nx == 5 && s.ny == 2 && s.width == 2.5 && s.height == 0.5 && s.mass == 0.3);
    CHECK(s.k_struct == 1500 && s.k_shear == 0 && s.k_bend == 0 && s.damping == 0);
    CHECK(s.gravity[0] == 0 && s.gravity[1] == -1.5 && s.gravity[2] == 9.81);
    CHECK(s.dt == 1e-3 && s.steps == 7 && s.frame_every == 3 && s.tilt == -90);
    CHECK(s.obstacle == OBSTACLE_FLOOR && s.floor_z == -0.25 && s.accuracy == 0.5);
    CHECK(s.npins == 2 && s.pin_i[0] == 4 && s.pin_j[0] == 1 && s.pin_i[1] == 0 && s.pin_j[1] == 0);
}

static void test_pins(void)
{
    cloth_scene s;
    /* corners_top before nx and ny: resolved once the file is read */
    if (PARSE_OK("pin = corners_top\npin = 2 1\n" BASE, &s))
        CHECK(s.npins == 3 && s.pin_i[0] == 0 && s.pin_j[0] == 2 && s.pin_i[1] == 3 && s.pin_j[1] == 2 &&
              s.pin_i[2] == 2 && s.pin_j[2] == 1);
    EXPECT_ERROR("pin = 4 0\n" BASE, "t:1: pin: (4, 0) is outside the 4 x 3 grid (0 <= i < 4, 0 <= j < 3)");
    EXPECT_ERROR(BASE "pin = 0 3\n", "t:4: pin: (0, 3) is outside the 4 x 3 grid (0 <= i < 4, 0 <= j < 3)");
    EXPECT_ERROR(BASE "pin = -1 2\n", "t:4: pin: (-1, 2) is outside the 4 x 3 grid (0 <= i < 4, 0 <= j < 3)");
    EXPECT_ERROR(BASE "pin = 0 2\npin = corners_top\n", "t:5: pin: (0, 2) is already pinned on line 4");
    EXPECT_ERROR(BASE "pin = 1\n", "t:4: pin: expected two integers 'i j' or 'corners_top', got '1'");
    EXPECT_ERROR(BASE "pin = 1 2 3\n", "t:4: pin: expected two integers 'i j' or 'corners_top', got '1 2 3'");
    EXPECT_ERROR(BASE "pin = corners_top 1\n",
                 "t:4: pin: expected two integers 'i j' or 'corners_top', got 'corners_top 1'");
    EXPECT_ERROR(BASE "pin = corners\n", "t:4: pin: expected two integers 'i j' or 'corners_top', got 'corners'");

    /* CLOTH_MAX_PINS pins fit, one more does not */
    char text[1024];
    size_t n = (size_t)snprintf(text, sizeof text, "nx = 20\nny = 2\naccuracy = 0.1\n");
    for (int i = 0; i < CLOTH_MAX_PINS; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "pin = %d 1\n", i);
    if (PARSE_OK(text, &s))
        CHECK(s.npins == CLOTH_MAX_PINS && s.pin_i[CLOTH_MAX_PINS - 1] == CLOTH_MAX_PINS - 1);
    snprintf(text + n, sizeof text - n, "pin = 0 0\n");
    char expected[64];
    snprintf(expected, sizeof expected, "t:%d: pin: too many pins (at most %d)", CLOTH_MAX_PINS + 4,
             CLOTH_MAX_PINS);
    EXPECT_ERROR(text, expected);
}

static void test_obstacles(void)
{
    cloth_scene s;
    if (PARSE_OK(BASE "obstacle = sphere 0.5 0.5 -0.35 0.3\n", &s))
        CHECK(s.obstacle == OBSTACLE_SPHERE && s.center[0] == 0.5 && s.center[1] == 0.5 && s.center[2] == -0.35 &&
              s.radius == 0.3);
    if (PARSE_OK(BASE "obstacle = none\n", &s))
        CHECK(s.obstacle == OBSTACLE_NONE);
    if (PARSE_OK(BASE "obstacle = floor -2\n", &s))
        CHECK(s.obstacle == OBSTACLE_FLOOR && s.floor_z == -2);
#define OBSTACLE_ERROR "t:4: obstacle: expected 'none', 'sphere cx cy cz r' with r > 0, or 'floor z', got "
    EXPECT_ERROR(BASE "obstacle = sphere 0 0 0 0\n", OBSTACLE_ERROR "'sphere 0 0 0 0'");
    EXPECT_ERROR(BASE "obstacle = sphere 1 2 3\n", OBSTACLE_ERROR "'sphere 1 2 3'");
    EXPECT_ERROR(BASE "obstacle = floor\n", OBSTACLE_ERROR "'floor'");
    EXPECT_ERROR(BASE "obstacle = floor 0 1\n", OBSTACLE_ERROR "'floor 0 1'");
    EXPECT_ERROR(BASE "obstacle = cube 1\n", OBSTACLE_ERROR "'cube 1'");
    EXPECT_ERROR(BASE "obstacle = nonesuch\n", OBSTACLE_ERROR "'nonesuch'");
}

static void test_bad_values(void)
{
    EXPECT_ERROR("nx = abc\n", "t:1: nx: expected an integer from 2 to 2000, got 'abc'");
    EXPECT_ERROR("nx = 1\n", "t:1: nx: expected an integer from 2 to 2000, got '1'");
    EXPECT_ERROR("ny = 2001\n", "t:1: ny: expected an integer from 2 to 2000, got '2001'");
    EXPECT_ERROR("nx = 4.0\n", "t:1: nx: expected an integer from 2 to 2000, got '4.0'");
    EXPECT_ERROR("nx = 4x\n", "t:1: nx: expected an integer from 2 to 2000, got '4x'");
    EXPECT_ERROR("nx = 4 4\n", "t:1: nx: expected an integer from 2 to 2000, got '4 4'");
    EXPECT_ERROR("nx =\n", "t:1: nx: expected an integer from 2 to 2000, got ''");
    EXPECT_ERROR("nx = 99999999999999999999\n",
                 "t:1: nx: expected an integer from 2 to 2000, got '99999999999999999999'");
    EXPECT_ERROR(BASE "width = 1.5 m\n", "t:4: width: expected a number > 0, got '1.5 m'");
    EXPECT_ERROR(BASE "width = 0\n", "t:4: width: expected a number > 0, got '0'");
    EXPECT_ERROR(BASE "width = nan\n", "t:4: width: expected a number > 0, got 'nan'");
    EXPECT_ERROR(BASE "dt = inf\n", "t:4: dt: expected a number > 0, got 'inf'");
    EXPECT_ERROR(BASE "tilt = 1e999\n", "t:4: tilt: expected a number, got '1e999'");
    EXPECT_ERROR(BASE "mass = -1\n", "t:4: mass: expected a number > 0, got '-1'");
    EXPECT_ERROR(BASE "k_struct = 0\n", "t:4: k_struct: expected a number > 0, got '0'");
    EXPECT_ERROR(BASE "k_shear = -1\n", "t:4: k_shear: expected a number >= 0, got '-1'");
    EXPECT_ERROR(BASE "damping = -0.1\n", "t:4: damping: expected a number >= 0, got '-0.1'");
    EXPECT_ERROR(BASE "gravity = 0 -9.81\n", "t:4: gravity: expected three numbers 'gx gy gz', got '0 -9.81'");
    EXPECT_ERROR(BASE "gravity = 0 0 -inf\n", "t:4: gravity: expected three numbers 'gx gy gz', got '0 0 -inf'");
    EXPECT_ERROR(BASE "steps = 0\n", "t:4: steps: expected an integer from 1 to 1000000000, got '0'");
    EXPECT_ERROR(BASE "frame_every = -1\n", "t:4: frame_every: expected an integer from 0 to 1000000000, got '-1'");
    EXPECT_ERROR("accuracy = 1\n", "t:1: accuracy: expected a number > 0 and < 1, got '1'");
    EXPECT_ERROR("accuracy = 0\n", "t:1: accuracy: expected a number > 0 and < 1, got '0'");
    EXPECT_ERROR(BASE "name = my scene\n",
                 "t:4: name: expected 1 to 63 letters, digits, '_', '-' or '.', got 'my scene'");
    EXPECT_ERROR(BASE "name = 0123456789012345678901234567890123456789012345678901234567890123\n",
                 "t:4: name: expected 1 to 63 letters, digits, '_', '-' or '.', got "
                 "'012345678901234567890123456789012345678901234567890123456789...'");
}

static void test_keys_and_lines(void)
{
    EXPECT_ERROR("kx = 4\n", "t:1: unknown key 'kx' (did you mean 'nx'?)");
    EXPECT_ERROR(BASE "acuracy = 0.1\n", "t:4: unknown key 'acuracy' (did you mean 'accuracy'?)");
    EXPECT_ERROR(BASE "frameevery = 2\n", "t:4: unknown key 'frameevery' (did you mean 'frame_every'?)");
    EXPECT_ERROR(BASE "pins = 1 1\n", "t:4: unknown key 'pins' (did you mean 'pin'?)");
    EXPECT_ERROR(BASE "NX = 4\n", "t:4: unknown key 'NX'");   /* two edits replace the whole key */
    EXPECT_ERROR(BASE "colour = red\n", "t:4: unknown key 'colour'");
    EXPECT_ERROR(BASE "k struct = 1\n", "t:4: unknown key 'k struct' (did you mean 'k_struct'?)");
    EXPECT_ERROR("nx 4\n", "t:1: expected 'key = value'");
    EXPECT_ERROR("# fine\n\n= 4\n", "t:3: expected 'key = value'");
    EXPECT_ERROR(BASE "nx = 5\n", "t:4: duplicate key 'nx' (already set on line 1)");
    EXPECT_ERROR("nx = 4\nny = 3\n", "t: missing required key 'accuracy'");
    EXPECT_ERROR("", "t: missing required key 'nx'");
    EXPECT_ERROR("# nothing but comments\naccuracy = 0.1 # and nx = 4\nny=2", "t: missing required key 'nx'");

    /* a key as long as a line is cut short in the message */
    char text[2100];
    memset(text, 'a', 100);
    strcpy(text + 100, " = 1\n");
    EXPECT_ERROR(text, "t:1: unknown key 'aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa...'");

    /* 1023 characters is the longest line; 2000 is an error naming its line */
    strcpy(text, BASE "#");
    size_t n = strlen(text);
    memset(text + n, 'x', 1022);
    strcpy(text + n + 1022, "\n");
    cloth_scene s;
    PARSE_OK(text, &s);
    strcpy(text, "nx = 4\n#");
    memset(text + 8, 'x', 1999);
    strcpy(text + 8 + 1999, "\nny = 3\n");
    EXPECT_ERROR(text, "t:2: line longer than 1023 characters");
}

/* err is filled only as far as errlen allows, and always ends in a NUL. */
static void test_small_err(void)
{
    cloth_scene s;
    char err[16];
    memset(err, '#', sizeof err);
    CHECK(scene_parse("nx = abc\n", "t", &s, err, 8) == -1);
    CHECK(strcmp(err, "t:1: nx") == 0 && err[8] == '#');
    memset(err, '#', sizeof err);
    CHECK(scene_parse("nx = abc\n", "a_long_origin_name", &s, err, 4) == -1);
    CHECK(strcmp(err, "a_l") == 0 && err[4] == '#');
    memset(err, '#', sizeof err);
    CHECK(scene_parse("nx = abc\n", "t", &s, err, 1) == -1 && err[0] == '\0' && err[1] == '#');
    CHECK(scene_parse("nx = abc\n", "t", &s, NULL, 0) == -1);
}

static void test_huge_text(void)
{
    size_t size = (1u << 20) + 1;
    char *text = malloc(size + 1);
    if (!CHECK(text != NULL))
        return;
    memset(text, '\n', size);
    text[size] = '\0';
    EXPECT_ERROR(text, "t: larger than 1 MiB");
    free(text);
}

static void test_scene_files(const char *dir)
{
    char path[4096], err[256];
    cloth_scene s;

    snprintf(path, sizeof path, "%s/hanging.scene", dir);
    int rc = scene_read(path, &s, err, sizeof err);
    if (rc != 0)
        printf("FAIL: %s\n", err);
    if (CHECK(rc == 0)) {
        CHECK(strcmp(s.name, "hanging") == 0 && s.nx == 32 && s.ny == 32 && s.width == 1 && s.height == 1);
        CHECK(s.k_struct == 2000 && s.k_shear == 200 && s.k_bend == 20 && s.damping == 0.2);
        CHECK(s.npins == 2 && s.pin_i[0] == 0 && s.pin_j[0] == 31 && s.pin_i[1] == 31 && s.pin_j[1] == 31);
        CHECK(s.tilt == 0 && s.obstacle == OBSTACLE_NONE && s.gravity[2] == -9.81);
        CHECK(s.dt == 0.005 && s.steps == 200 && s.frame_every == 20 && s.accuracy == 1e-3);
    }

    snprintf(path, sizeof path, "%s/large.scene", dir);
    rc = scene_read(path, &s, err, sizeof err);
    if (rc != 0)
        printf("FAIL: %s\n", err);
    if (CHECK(rc == 0)) {
        CHECK(strcmp(s.name, "large") == 0 && s.nx == 100 && s.ny == 100 && s.width == 2 && s.height == 2);
        CHECK(s.mass == 4 && s.npins == 2 && s.pin_i[1] == 99 && s.pin_j[1] == 99);
        CHECK(s.steps == 50 && s.frame_every == 10 && s.accuracy == 1e-3);
    }

    snprintf(path, sizeof path, "%s/drape.scene", dir);
    rc = scene_read(path, &s, err, sizeof err);
    if (rc != 0)
        printf("FAIL: %s\n", err);
    if (CHECK(rc == 0)) {
        CHECK(strcmp(s.name, "drape") == 0 && s.nx == 32 && s.ny == 32 && s.npins == 0);
        CHECK(s.obstacle == OBSTACLE_SPHERE && s.center[0] == 0.5 && s.center[1] == 0.5 &&
              s.center[2] == -0.35 && s.radius == 0.3);
        CHECK(s.gravity[0] == 0 && s.gravity[1] == 0 && s.gravity[2] == -9.81);
        CHECK(s.steps == 300 && s.frame_every == 30 && s.accuracy == 1e-2);
    }

    snprintf(path, sizeof path, "%s/no_such.scene", dir);
    char expected[4400];
    snprintf(expected, sizeof expected, "%s: cannot open: No such file or directory", path);
    CHECK(scene_read(path, &s, err, sizeof err) == -1 && strncmp(err, expected, sizeof err - 1) == 0);
}

/* Files that only a file can give: a default name, a NUL byte, too many bytes. */
static void test_odd_files(void)
{
    char dir[] = "/tmp/test_scene_XXXXXX";
    if (!CHECK(mkdtemp(dir) != NULL))
        return;
    char path[64], expected[128], err[256];
    cloth_scene s;
    FILE *f;

    snprintf(path, sizeof path, "%s/plain.scene", dir);
    if ((f = fopen(path, "wb")) != NULL) {
        fputs(BASE, f);
        fclose(f);
    }
    CHECK(scene_read(path, &s, err, sizeof err) == 0 && strcmp(s.name, "plain") == 0);

    if ((f = fopen(path, "wb")) != NULL) {
        fputs(BASE "# a NUL", f);
        fputc('\0', f);
        fputs("\nsteps = 3\n", f);
        fclose(f);
    }
    snprintf(expected, sizeof expected, "%s:4: contains a NUL byte", path);
    CHECK(scene_read(path, &s, err, sizeof err) == -1 && strcmp(err, expected) == 0);

    if ((f = fopen(path, "wb")) != NULL) {
        for (int i = 0; i <= 1 << 20; i++)
            fputc('\n', f);
        fclose(f);
    }
    snprintf(expected, sizeof expected, "%s: larger than 1 MiB", path);
    CHECK(scene_read(path, &s, err, sizeof err) == -1 && strcmp(err, expected) == 0);

    snprintf(expected, sizeof expected, "%s: cannot read: Is a directory", dir);
    CHECK(scene_read(dir, &s, err, sizeof err) == -1 && strcmp(err, expected) == 0);

    remove(path);
    rmdir(dir);
}

/* One line per key, each starting "  KEY = ". */
static void test_print_keys(void)
{
    static const char *names[] = {"name", "nx", "ny", "width", "height", "mass", "k_struct", "k_shear", "k_bend",
                                  "damping", "gravity", "dt", "steps", "frame_every", "pin", "tilt", "obstacle",
                                  "accuracy", "max_stretch"};
    enum { KEYS = sizeof names / sizeof names[0] };
    FILE *f = tmpfile();
    if (!CHECK(f != NULL))
        return;
    scene_print_keys(f);
    rewind(f);
    char line[512];
    int lines = 0;
    bool all_match = true;
    while (fgets(line, sizeof line, f) != NULL) {
        char start[32];
        snprintf(start, sizeof start, "  %s = ", lines < KEYS ? names[lines] : "?");
        all_match = all_match && strncmp(line, start, strlen(start)) == 0 && strchr(line, '\n') != NULL;
        lines++;
    }
    fclose(f);
    CHECK(lines == KEYS && all_match);
}

int main(int argc, char **argv)
{
    /* The scenes' folder: the argument, else SILC_CLOTH_SCENES (ctest). */
    const char *scenes = argc > 1 ? argv[1] : getenv("SILC_CLOTH_SCENES");
    if (argc > 2 || !scenes) {
        fprintf(stderr, "usage: %s SCENE_DIR (or set SILC_CLOTH_SCENES)\n", argv[0]);
        return 2;
    }
    test_defaults();
    test_every_key();
    test_pins();
    test_obstacles();
    test_bad_values();
    test_unsimulable();
    test_keys_and_lines();
    test_small_err();
    test_huge_text();
    test_scene_files(scenes);
    test_odd_files();
    test_print_keys();
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}
