/* The per-step path of an FMU in instructions: run under callgrind (bench/c/callgrind), which
 * counts fmi2DoStep inclusive and the whole SetReal/DoStep/GetReal loop.
 *
 *   step_host <library> <GUID> <steps> <input vr> <output vr> [<Integer vr>=<value> ...]
 *             [R:<Real vr>=<value> ...] [H=<communication step>]
 *
 * Instantiates, sets the Integer parameters (e.g. TLD's model) and Real ones, initialises, then per step sets
 * the input to a harmonic value, steps by 0.01 s (or H) and reads the output. */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *comp_t;
typedef void (*logger_t)(void *, const char *, int, const char *, const char *, ...);
typedef struct { logger_t logger; void *allocate; void *free; void *step_finished; void *env; } callbacks_t;
static void logger(void *env, const char *name, int status, const char *category, const char *fmt, ...) {
    (void)env; (void)name; (void)category; (void)fmt;
    if (status > 1) fprintf(stderr, "FMU reported status %d\n", status);
}
typedef comp_t (*inst_t)(const char *, int, const char *, const char *, const callbacks_t *, int, int);
typedef int (*comp_f)(comp_t);
typedef int (*setup_t)(comp_t, int, double, double, int, double);
typedef int (*setr_t)(comp_t, const unsigned *, size_t, const double *);
typedef int (*seti_t)(comp_t, const unsigned *, size_t, const int *);
typedef int (*getr_t)(comp_t, const unsigned *, size_t, double *);
typedef int (*step_t)(comp_t, double, double, int);
typedef void (*free_t)(comp_t);

int main(int argc, char **argv) {
    if (argc < 6) { fprintf(stderr, "usage: step_host LIB GUID STEPS IN_VR OUT_VR [VR=INT ...]\n"); return 2; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    inst_t instantiate = (inst_t)dlsym(lib, "fmi2Instantiate");
    setup_t setup = (setup_t)dlsym(lib, "fmi2SetupExperiment");
    comp_f enter = (comp_f)dlsym(lib, "fmi2EnterInitializationMode");
    comp_f exit_ = (comp_f)dlsym(lib, "fmi2ExitInitializationMode");
    setr_t set_real = (setr_t)dlsym(lib, "fmi2SetReal");
    seti_t set_integer = (seti_t)dlsym(lib, "fmi2SetInteger");
    getr_t get_real = (getr_t)dlsym(lib, "fmi2GetReal");
    step_t do_step = (step_t)dlsym(lib, "fmi2DoStep");
    free_t free_instance = (free_t)dlsym(lib, "fmi2FreeInstance");
    callbacks_t cb = { logger, NULL, NULL, NULL, NULL };
    comp_t c = instantiate("steps", 1, argv[2], NULL, &cb, 0, 0);
    if (!c) return 1;
    int steps = atoi(argv[3]);
    unsigned in = (unsigned)atoi(argv[4]), out = (unsigned)atoi(argv[5]);
    if (setup(c, 0, 0.0, 0.0, 0, 0.0) || enter(c)) return 1;
    double h = 0.01;
    for (int i = 6; i < argc; i++) {
        unsigned vr; int value; double real;
        if (sscanf(argv[i], "H=%lf", &real) == 1) {
            h = real;
        } else if (sscanf(argv[i], "R:%u=%lf", &vr, &real) == 2) {
            if (set_real(c, &vr, 1, &real)) return 1;
        } else if (sscanf(argv[i], "%u=%d", &vr, &value) != 2 || set_integer(c, &vr, 1, &value)) {
            return 1;
        }
    }
    if (exit_(c)) return 1;
    double t = 0.0, y = 0.0, sum = 0.0;
    for (int k = 0; k < steps; k++) {
        double a = 0.5 * sin(5.0 * t);
        if (set_real(c, &in, 1, &a) || do_step(c, t, h, 1) || get_real(c, &out, 1, &y)) return 1;
        sum += y;
        t += h;
    }
    printf("step_host: %d steps, sum of outputs %.9e\n", steps, sum);
    free_instance(c);
    return 0;
}
