/*
 * scene.c -- reads the cloth example's scene files (scenes/NAME.scene) into a
 * cloth_scene.  A scene is text, one `key = value` per line, `#` to the end
 * of a line is a comment, blank lines and the spaces around keys and values
 * do not count.  The keys are the table below, which is also the help that
 * scene_print_keys shows.  Scene files come from users, so nothing here
 * trusts them: a line and a file have fixed size limits, numbers must be
 * whole and finite, and every mistake becomes a message naming the file, the
 * line and the key instead of a crash or a silently odd simulation.
 */
#include "cloth.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

enum {
    SCENE_LINE_MAX = 1024,        /* a line, with its terminating NUL: 1023 characters */
    SCENE_FILE_MAX = 1 << 20,     /* a scene file or string: 1 MiB */
    SCENE_COUNT_MAX = 1000000000, /* steps, frame_every, pin indices: fits an int with room */
    SCENE_QUOTE_MAX = 60,         /* characters of a bad key or value repeated in a message */
    SCENE_KEY_LEN_MAX = 16,       /* longer than every key: no suggestion needed */
};

typedef enum {
    KEY_NAME,
    KEY_NX,
    KEY_NY,
    KEY_WIDTH,
    KEY_HEIGHT,
    KEY_MASS,
    KEY_K_STRUCT,
    KEY_K_SHEAR,
    KEY_K_BEND,
    KEY_DAMPING,
    KEY_GRAVITY,
    KEY_DT,
    KEY_STEPS,
    KEY_FRAME_EVERY,
    KEY_PIN,
    KEY_TILT,
    KEY_OBSTACLE,
    KEY_ACCURACY,
    KEY_MAX_STRETCH,
    KEY_COUNT
} scene_key;

/* One row per key.  `expected` finishes the message "KEY: expected ..., got
 * 'VALUE'"; `usage` and `help` are its line in scene_print_keys.  The
 * defaults named in `help` are set in set_defaults. */
static const struct {
    const char *name, *expected, *usage, *help;
} keys[KEY_COUNT] = {
    [KEY_NAME] = {"name", "1 to 63 letters, digits, '_', '-' or '.'", "WORD",
                  "what the scene is called in output (default: the file name without .scene)"},
    [KEY_NX] = {"nx", "an integer from 2 to 2000", "N",
                "particles along x, the width (2 to 2000; required)"},
    [KEY_NY] = {"ny", "an integer from 2 to 2000", "N",
                "particles along y, the height (2 to 2000; required)"},
    [KEY_WIDTH] = {"width", "a number > 0", "M", "cloth size along x in metres, > 0 (default 1)"},
    [KEY_HEIGHT] = {"height", "a number > 0", "M", "cloth size along y in metres, > 0 (default 1)"},
    [KEY_MASS] = {"mass", "a number > 0", "KG",
                  "total mass in kg, shared equally by the particles, > 0 (default 1)"},
    [KEY_K_STRUCT] = {"k_struct", "a number > 0", "N/M",
                      "stiffness of the structural springs (grid neighbours) in N/m, > 0 (default 1000)"},
    [KEY_K_SHEAR] = {"k_shear", "a number >= 0", "N/M",
                     "stiffness of the shear springs (diagonals) in N/m, >= 0 (default 100)"},
    [KEY_K_BEND] = {"k_bend", "a number >= 0", "N/M",
                    "stiffness of the bend springs (second neighbours) in N/m, >= 0, 0 for none (default 10)"},
    [KEY_DAMPING] = {"damping", "a number >= 0", "RATE",
                     "velocity damping in 1/s (the force is -damping * mass * velocity), >= 0 (default 0.1)"},
    [KEY_GRAVITY] = {"gravity", "three numbers 'gx gy gz'", "GX GY GZ",
                     "gravity in m/s^2 (default 0 0 -9.81)"},
    [KEY_DT] = {"dt", "a number > 0", "S", "time step in seconds, > 0 (default 0.005)"},
    [KEY_STEPS] = {"steps", "an integer from 1 to 1000000000", "N",
                   "time steps to run, >= 1 (default 100)"},
    [KEY_FRAME_EVERY] = {"frame_every", "an integer from 0 to 1000000000", "N",
                         "write a picture every N steps, 0 for none (default 0)"},
    [KEY_PIN] = {"pin", "two integers 'i j' or 'corners_top'", "I J",
                 "hold particle (i, j) still, 0 <= i < nx, 0 <= j < ny; may repeat, at most 16 pins; "
                 "'pin = corners_top' pins (0, ny-1) and (nx-1, ny-1) (default: none)"},
    [KEY_TILT] = {"tilt", "a number", "DEG",
                  "the cloth starts flat in z = 0 (x from 0 to width, y from 0 to height) turned this many "
                  "degrees about the x axis; 90 turns +y into +z, standing it in the x-z plane (default 0)"},
    [KEY_OBSTACLE] = {"obstacle", "'none', 'sphere cx cy cz r' with r > 0, or 'floor z'", "KIND ...",
                      "'none', 'sphere CX CY CZ R' (centre and radius in metres, R > 0) or 'floor Z' "
                      "(the plane z = Z) (default none)"},
    [KEY_ACCURACY] = {"accuracy", "a number > 0 and < 1", "REL",
                      "how far a particle may be off after the run, relative to the cloth size, "
                      "> 0 and < 1 (required)"},
    [KEY_MAX_STRETCH] = {"max_stretch", "a number > 1", "RATIO",
                         "the longest a spring may get over its rest length before the program warns, > 1 "
                         "(default 1.5)"},
};

/* The help for `pin` spells the limit out. */
_Static_assert(CLOTH_MAX_PINS == 16, "update the help for 'pin' in keys[]");

static const scene_key required_keys[] = {KEY_NX, KEY_NY, KEY_ACCURACY};

/* `pin = corners_top` may come before nx and ny, so its pins are resolved at
 * the end of the file; until then they are marked by where they go. */
typedef enum { PIN_AS_GIVEN, PIN_TOP_LEFT, PIN_TOP_RIGHT } pin_place;

typedef struct {
    const char *origin; /* the file name (or a string's name) in messages */
    char *err;
    size_t errlen;
    int line;                       /* the line being read, from 1 */
    int key_line[KEY_COUNT];        /* where each key was set, 0 if not yet */
    int pin_line[CLOTH_MAX_PINS];   /* where each pin was set */
    pin_place pin_place[CLOTH_MAX_PINS];
} parser;

#if defined(__GNUC__)
#define PRINTF_LIKE(f, a) __attribute__((format(printf, f, a)))
#else
#define PRINTF_LIKE(f, a)
#endif

/* Writes "ORIGIN:LINE: message" (or "ORIGIN: message" when line is 0) into
 * err, cut short if err is small, and returns -1 for `return fail(...)`. */
PRINTF_LIKE(3, 4) static int fail(const parser *p, int line, const char *fmt, ...)
{
    if (p->err == NULL || p->errlen == 0)
        return -1;
    int n = line > 0 ? snprintf(p->err, p->errlen, "%s:%d: ", p->origin, line)
                     : snprintf(p->err, p->errlen, "%s: ", p->origin);
    if (n >= 0 && (size_t)n < p->errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(p->err + n, p->errlen - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* A bad key or value is repeated in its message, but only its start: that is
 * enough to find it, and a 1000-character value would drown the message. */
static const char *shortened(const char *text, char out[SCENE_QUOTE_MAX + 4])
{
    snprintf(out, SCENE_QUOTE_MAX + 4, "%.*s%s", SCENE_QUOTE_MAX, text,
             strlen(text) > SCENE_QUOTE_MAX ? "..." : "");
    return out;
}

static int bad_value(const parser *p, scene_key k, const char *value)
{
    char quote[SCENE_QUOTE_MAX + 4];
    return fail(p, p->line, "%s: expected %s, got '%s'", keys[k].name, keys[k].expected,
                shortened(value, quote));
}

/* ---- words and numbers --------------------------------------------------- */

/* Not isspace: that depends on the locale, and a scene should not. */
static bool is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static const char *skip_space(const char *c)
{
    while (is_space(*c))
        c++;
    return c;
}

/* Cuts the spaces off both ends of s, in place. */
static char *trim(char *s)
{
    s = (char *)skip_space(s);
    size_t n = strlen(s);
    while (n > 0 && is_space(s[n - 1]))
        n--;
    s[n] = '\0';
    return s;
}

/* A number must end where its word ends: "4x" and "1.5m" are not numbers. */
static bool at_word_end(const char *c)
{
    return *c == '\0' || is_space(*c);
}

/* Each reader takes the next word at *c and on success moves *c past it. */

static bool read_word(const char **c, const char *word)
{
    const char *start = skip_space(*c);
    size_t n = strlen(word);
    if (strncmp(start, word, n) != 0 || !at_word_end(start + n))
        return false;
    *c = start + n;
    return true;
}

static bool read_int(const char **c, int min, int max, int *out)
{
    const char *start = skip_space(*c);
    const char *digits = start + (*start == '-' || *start == '+');
    if (*digits < '0' || *digits > '9')
        return false;
    char *end;
    errno = 0;
    long v = strtol(start, &end, 10);
    if (errno == ERANGE || v < min || v > max || !at_word_end(end))
        return false;
    *out = (int)v;
    *c = end;
    return true;
}

/* strtod follows the C locale here (the program does not call setlocale),
 * so the decimal mark is always '.'.  nan, inf and overflow are refused: a
 * scene with them would only fail later, and less clearly. */
static bool read_real(const char **c, double *out)
{
    const char *start = skip_space(*c);
    char *end;
    double v = strtod(start, &end);
    if (end == start || !isfinite(v) || !at_word_end(end))
        return false;
    *out = v;
    *c = end;
    return true;
}

/* ---- keys ---------------------------------------------------------------- */

/* Levenshtein distance, kept in one row of a fixed table since keys are
 * short; anything longer than every key is simply far from all of them. */
static int edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > SCENE_KEY_LEN_MAX || lb > SCENE_KEY_LEN_MAX)
        return SCENE_KEY_LEN_MAX + 1;
    int row[SCENE_KEY_LEN_MAX + 1];
    for (size_t j = 0; j <= lb; j++)
        row[j] = (int)j;
    for (size_t i = 1; i <= la; i++) {
        int diagonal = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= lb; j++) {
            int above = row[j];
            int best = diagonal + (a[i - 1] != b[j - 1]);
            if (above + 1 < best)
                best = above + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            row[j] = best;
            diagonal = above;
        }
    }
    return row[lb];
}

/* The known key nearest to a misspelt one, if it is at most two edits away
 * and the edits do not replace the whole key ("zz" is not a typo of "nx");
 * on a tie the first in the table wins. */
static const char *suggestion(const char *key)
{
    const char *best = NULL;
    int best_distance = 3;
    for (int k = 0; k < KEY_COUNT; k++) {
        int d = edit_distance(key, keys[k].name);
        if (d < best_distance && d < (int)strlen(keys[k].name)) {
            best = keys[k].name;
            best_distance = d;
        }
    }
    return best;
}

/* Names may end up in file names, so they are plain words. */
static bool read_name(const char **c, cloth_scene *s)
{
    static const char allowed[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.";
    size_t n = strlen(*c);
    if (n == 0 || n >= sizeof s->name || strspn(*c, allowed) != n)
        return false;
    memcpy(s->name, *c, n + 1);
    *c += n;
    return true;
}

static bool read_obstacle(const char **c, cloth_scene *s)
{
    if (read_word(c, "none")) {
        s->obstacle = OBSTACLE_NONE;
        return true;
    }
    if (read_word(c, "sphere")) {
        s->obstacle = OBSTACLE_SPHERE;
        return read_real(c, &s->center[0]) && read_real(c, &s->center[1]) && read_real(c, &s->center[2]) &&
               read_real(c, &s->radius) && s->radius > 0;
    }
    if (read_word(c, "floor")) {
        s->obstacle = OBSTACLE_FLOOR;
        return read_real(c, &s->floor_z);
    }
    return false;
}

/* Pins may come before nx and ny, so only their form is checked here; where
 * they are is checked in finish. */
static int add_pin(parser *p, const char *value, cloth_scene *s)
{
    const char *c = value;
    int i = 0, j = 0;
    bool corners = read_word(&c, "corners_top");
    if (!corners && !(read_int(&c, -SCENE_COUNT_MAX, SCENE_COUNT_MAX, &i) &&
                      read_int(&c, -SCENE_COUNT_MAX, SCENE_COUNT_MAX, &j)))
        return bad_value(p, KEY_PIN, value);
    if (*c != '\0')
        return bad_value(p, KEY_PIN, value);
    int needed = corners ? 2 : 1;
    if (s->npins + needed > CLOTH_MAX_PINS)
        return fail(p, p->line, "pin: too many pins (at most %d)", CLOTH_MAX_PINS);
    for (int n = 0; n < needed; n++) {
        int at = s->npins++;
        s->pin_i[at] = i;
        s->pin_j[at] = j;
        p->pin_line[at] = p->line;
        p->pin_place[at] = !corners ? PIN_AS_GIVEN : n == 0 ? PIN_TOP_LEFT : PIN_TOP_RIGHT;
    }
    return 0;
}

static int set_value(parser *p, scene_key k, const char *value, cloth_scene *s)
{
    if (k == KEY_PIN)
        return add_pin(p, value, s);
    const char *c = value;
    bool ok = false;
    switch (k) {
    case KEY_NAME: ok = read_name(&c, s); break;
    case KEY_NX: ok = read_int(&c, 2, 2000, &s->nx); break;
    case KEY_NY: ok = read_int(&c, 2, 2000, &s->ny); break;
    case KEY_WIDTH: ok = read_real(&c, &s->width) && s->width > 0; break;
    case KEY_HEIGHT: ok = read_real(&c, &s->height) && s->height > 0; break;
    case KEY_MASS: ok = read_real(&c, &s->mass) && s->mass > 0; break;
    case KEY_K_STRUCT: ok = read_real(&c, &s->k_struct) && s->k_struct > 0; break;
    case KEY_K_SHEAR: ok = read_real(&c, &s->k_shear) && s->k_shear >= 0; break;
    case KEY_K_BEND: ok = read_real(&c, &s->k_bend) && s->k_bend >= 0; break;
    case KEY_DAMPING: ok = read_real(&c, &s->damping) && s->damping >= 0; break;
    case KEY_GRAVITY:
        ok = read_real(&c, &s->gravity[0]) && read_real(&c, &s->gravity[1]) && read_real(&c, &s->gravity[2]);
        break;
    case KEY_DT: ok = read_real(&c, &s->dt) && s->dt > 0; break;
    case KEY_STEPS: ok = read_int(&c, 1, SCENE_COUNT_MAX, &s->steps); break;
    case KEY_FRAME_EVERY: ok = read_int(&c, 0, SCENE_COUNT_MAX, &s->frame_every); break;
    case KEY_TILT: ok = read_real(&c, &s->tilt); break;
    case KEY_OBSTACLE: ok = read_obstacle(&c, s); break;
    case KEY_ACCURACY: ok = read_real(&c, &s->accuracy) && s->accuracy > 0 && s->accuracy < 1; break;
    case KEY_MAX_STRETCH: ok = read_real(&c, &s->max_stretch) && s->max_stretch > 1; break;
    case KEY_PIN:
    case KEY_COUNT: break;
    }
    /* Every reader stops after its last word, so anything left is garbage. */
    return ok && *c == '\0' ? 0 : bad_value(p, k, value);
}

/* ---- lines and files ----------------------------------------------------- */

static int parse_line(parser *p, char *line, cloth_scene *s)
{
    char *comment = strchr(line, '#');
    if (comment != NULL)
        *comment = '\0';
    char *equals = strchr(line, '=');
    if (equals == NULL)
        return *trim(line) == '\0' ? 0 : fail(p, p->line, "expected 'key = value'");
    *equals = '\0';
    char *key = trim(line), *value = trim(equals + 1);
    if (*key == '\0')
        return fail(p, p->line, "expected 'key = value'");

    int k = 0;
    while (k < KEY_COUNT && strcmp(key, keys[k].name) != 0)
        k++;
    if (k == KEY_COUNT) {
        char quote[SCENE_QUOTE_MAX + 4];
        const char *near = suggestion(key);
        if (near != NULL)
            return fail(p, p->line, "unknown key '%s' (did you mean '%s'?)", shortened(key, quote), near);
        return fail(p, p->line, "unknown key '%s'", shortened(key, quote));
    }
    if (k != KEY_PIN && p->key_line[k] != 0)
        return fail(p, p->line, "duplicate key '%s' (already set on line %d)", key, p->key_line[k]);
    p->key_line[k] = p->line;
    return set_value(p, (scene_key)k, value, s);
}

/* Values that read well but cannot be simulated, each with the criterion:
 *   - a mass per area below 1e-6 kg/m^2 (a soap film is about 1e-3): no
 *     cloth is that light, and the mass term vanishes from the system;
 *   - a step in which free fall alone, |g| dt^2 / 2, covers more than the
 *     cloth's size: the step cannot resolve the motion it simulates;
 *   - a system whose condition bound (1 + 2 dt^2 sum k / ((1 + dt damping)
 *     m), the Gershgorin bound of cloth_condition_bound for the stiffest
 *     particle) times the double-precision unit roundoff 1.1e-16 exceeds
 *     the accuracy: no solver can give dv to the accuracy. */
static int check_simulable(const parser *p, const cloth_scene *s)
{
    double size = fmax(s->width, s->height), density = s->mass / (s->width * s->height);
    double g = sqrt(s->gravity[0] * s->gravity[0] + s->gravity[1] * s->gravity[1] + s->gravity[2] * s->gravity[2]);
    double mp = s->mass / ((double)s->nx * s->ny), ksum = 4 * (s->k_struct + s->k_shear + s->k_bend);
    double cond = 1 + 2 * s->dt * s->dt * ksum / ((1 + s->dt * s->damping) * mp);
    if (!(density >= 1e-6))
        return fail(p, p->key_line[KEY_MASS], "mass: %g kg over %g m^2 is %g kg/m^2, below the floor of 1e-6 kg/m^2 "
                    "(a soap film weighs about 1e-3): too light to simulate", s->mass, s->width * s->height, density);
    if (g * s->dt * s->dt / 2 > size)
        return fail(p, p->key_line[KEY_DT], "dt: in one step of %g s free fall alone covers %.3g m, more than the "
                    "cloth's size %g m: the step is meaningless (|g| dt^2 / 2 must stay below the size; dt <= %.3g s)",
                    s->dt, g * s->dt * s->dt / 2, size, sqrt(2 * size / g));
    if (!(cond * 1.1e-16 <= s->accuracy))
        return fail(p, 0, "the system's condition bound %.3g (dt %g s, springs up to %g N/m on particles of %g kg) "
                    "times the unit roundoff 1.1e-16 exceeds the accuracy %g: no solve in double precision can "
                    "reach it (a smaller dt, softer springs or a heavier cloth)", cond, s->dt,
                    fmax(s->k_struct, fmax(s->k_shear, s->k_bend)), mp, s->accuracy);
    return 0;
}

/* What can only be checked once the whole file is read. */
static int finish(parser *p, cloth_scene *s)
{
    for (size_t r = 0; r < sizeof required_keys / sizeof required_keys[0]; r++)
        if (p->key_line[required_keys[r]] == 0)
            return fail(p, 0, "missing required key '%s'", keys[required_keys[r]].name);
    for (int n = 0; n < s->npins; n++) {
        if (p->pin_place[n] != PIN_AS_GIVEN) {
            s->pin_i[n] = p->pin_place[n] == PIN_TOP_LEFT ? 0 : s->nx - 1;
            s->pin_j[n] = s->ny - 1;
        }
        int i = s->pin_i[n], j = s->pin_j[n];
        if (i < 0 || i >= s->nx || j < 0 || j >= s->ny)
            return fail(p, p->pin_line[n], "pin: (%d, %d) is outside the %d x %d grid (0 <= i < %d, 0 <= j < %d)",
                        i, j, s->nx, s->ny, s->nx, s->ny);
        /* Pinning a particle twice is harmless but almost surely a typo. */
        for (int m = 0; m < n; m++)
            if (s->pin_i[m] == i && s->pin_j[m] == j)
                return fail(p, p->pin_line[n], "pin: (%d, %d) is already pinned on line %d", i, j,
                            p->pin_line[m]);
    }
    return check_simulable(p, s);
}

static void set_defaults(cloth_scene *s, const char *name, size_t name_len)
{
    *s = (cloth_scene){.width = 1, .height = 1, .mass = 1, .k_struct = 1000, .k_shear = 100, .k_bend = 10,
                       .damping = 0.1, .gravity = {0, 0, -9.81}, .dt = 0.005, .steps = 100, .max_stretch = 1.5,
                       .obstacle = OBSTACLE_NONE};
    if (name_len >= sizeof s->name)
        name_len = sizeof s->name - 1;
    memcpy(s->name, name, name_len);
    s->name[name_len] = '\0';
}

static int parse(const char *text, const char *origin, const char *name, size_t name_len, cloth_scene *s,
                 char *err, size_t errlen)
{
    parser p = {.origin = origin, .err = err, .errlen = errlen};
    if (err != NULL && errlen > 0)
        err[0] = '\0';
    set_defaults(s, name, name_len);

    /* The same limit as for files, which also keeps the line count an int. */
    size_t size = 0;
    while (size <= SCENE_FILE_MAX && text[size] != '\0')
        size++;
    if (size > SCENE_FILE_MAX)
        return fail(&p, 0, "larger than 1 MiB");

    const char *at = text;
    for (p.line = 1; *at != '\0'; p.line++) {
        size_t len = strcspn(at, "\n");
        const char *next = at[len] == '\n' ? at + len + 1 : at + len;
        if (len > 0 && at[len - 1] == '\r')
            len--;
        if (len >= SCENE_LINE_MAX)
            return fail(&p, p.line, "line longer than %d characters", SCENE_LINE_MAX - 1);
        char line[SCENE_LINE_MAX];
        memcpy(line, at, len);
        line[len] = '\0';
        if (parse_line(&p, line, s) != 0)
            return -1;
        at = next;
    }
    return finish(&p, s);
}

int scene_parse(const char *text, const char *origin, cloth_scene *s, char *err, size_t errlen)
{
    if (origin == NULL)
        origin = "scene";
    return parse(text, origin, origin, strlen(origin), s, err, errlen);
}

int scene_read(const char *path, cloth_scene *s, char *err, size_t errlen)
{
    parser p = {.origin = path, .err = err, .errlen = errlen};
    FILE *f = fopen(path, "rb");
    if (f == NULL)
        return fail(&p, 0, "cannot open: %s", strerror(errno));
    /* One byte more than allowed tells a file at the limit from a larger one. */
    char *text = malloc(SCENE_FILE_MAX + 2);
    if (text == NULL) {
        fclose(f);
        return fail(&p, 0, "out of memory");
    }
    errno = 0;
    size_t size = fread(text, 1, SCENE_FILE_MAX + 1, f);
    bool read_failed = ferror(f) != 0;
    int read_error = errno;
    fclose(f);
    const char *nul = memchr(text, '\0', size);
    int rc;
    if (read_failed) {
        rc = fail(&p, 0, "cannot read: %s", strerror(read_error));
    } else if (size > SCENE_FILE_MAX) {
        rc = fail(&p, 0, "larger than 1 MiB");
    } else if (nul != NULL) {
        /* As text it would end at the NUL and silently drop the rest. */
        int line = 1;
        for (const char *c = text; c < nul; c++)
            line += *c == '\n';
        rc = fail(&p, line, "contains a NUL byte");
    } else {
        text[size] = '\0';
        /* The default name is the file's base name without ".scene". */
        const char *slash = strrchr(path, '/');
        const char *base = slash != NULL ? slash + 1 : path;
        size_t base_len = strlen(base);
        if (base_len > 6 && strcmp(base + base_len - 6, ".scene") == 0)
            base_len -= 6;
        rc = parse(text, path, base, base_len, s, err, errlen);
    }
    free(text);
    return rc;
}

void scene_print_keys(FILE *out)
{
    for (int k = 0; k < KEY_COUNT; k++) {
        char usage[40];
        snprintf(usage, sizeof usage, "%s = %s", keys[k].name, keys[k].usage);
        fprintf(out, "  %-22s %s\n", usage, keys[k].help);
    }
}
