/* A plain C FMI host for resource checks: run it under valgrind (scripts/leakcheck).
 *
 *   leak_host <path to TLD.so> <GUID> <cycles>
 *
 * Each cycle instantiates, initialises, steps, saves/serialises/restores the FMU state, makes a
 * few refused calls (so the error and logging paths run too), terminates and frees. With
 * -DVR_CYCLE=vr -DCYCLE_N=n, cycle k first sets the Integer parameter vr to 1 + k % n (TLD.fmu:
 * every model in turn; Building.fmu: 1 to 20 storeys), so every configuration's allocations are
 * checked; -DVR_EXTRA=vr -DEXTRA_VALUE=v sets one more Integer parameter in every cycle (TLD.fmu:
 * 16 shallow-water cells, enough to allocate everything and cheap under valgrind). Afterwards it
 * measures the heap one initialised instance holds, from 1000 live instances at once.
 * Exit status 0 = all calls returned the expected status. */
#include <dlfcn.h>
#include <malloc.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if !defined(VR_BASE_A) || !defined(VR_SLOSH_X) || !defined(VR_ETA)
#error "compile with -DVR_BASE_A=.. -DVR_SLOSH_X=.. -DVR_ETA=.. (scripts/leakcheck reads them from modelDescription.xml)"
#endif

typedef void *comp_t;
typedef void (*logger_t)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    logger_t logger;
    void *allocate;
    void *free;
    void *step_finished;
    void *env;
} callbacks_t;

static unsigned long messages;

static void logger(void *env, const char *name, int status, const char *category, const char *fmt, ...) {
    char buffer[1024];
    va_list args;
    va_start(args, fmt);
    vsnprintf(buffer, sizeof buffer, fmt, args);
    va_end(args);
    (void)env; (void)name; (void)status; (void)category;
    messages++;
}

#define LOAD(name) name##_t name = (name##_t)dlsym(lib, #name); if (!name) { fprintf(stderr, "missing %s\n", #name); return 2; }
typedef comp_t (*fmi2Instantiate_t)(const char *, int, const char *, const char *, const callbacks_t *, int, int);
typedef void (*fmi2FreeInstance_t)(comp_t);
typedef int (*fmi2SetupExperiment_t)(comp_t, int, double, double, int, double);
typedef int (*fmi2EnterInitializationMode_t)(comp_t);
typedef int (*fmi2ExitInitializationMode_t)(comp_t);
typedef int (*fmi2Terminate_t)(comp_t);
typedef int (*fmi2SetReal_t)(comp_t, const unsigned *, size_t, const double *);
typedef int (*fmi2GetReal_t)(comp_t, const unsigned *, size_t, double *);
typedef int (*fmi2DoStep_t)(comp_t, double, double, int);
typedef int (*fmi2GetFMUstate_t)(comp_t, void **);
typedef int (*fmi2SetFMUstate_t)(comp_t, void *);
typedef int (*fmi2FreeFMUstate_t)(comp_t, void **);
typedef int (*fmi2SerializedFMUstateSize_t)(comp_t, void *, size_t *);
typedef int (*fmi2SerializeFMUstate_t)(comp_t, void *, char *, size_t);
typedef int (*fmi2DeSerializeFMUstate_t)(comp_t, const char *, size_t, void **);
typedef int (*fmi2SetInteger_t)(comp_t, const unsigned *, size_t, const int *);

#define CHECK(call, want) do { int s_ = (call); if (s_ != (want)) { \
    fprintf(stderr, "%s returned %d, expected %d (cycle %d)\n", #call, s_, (want), cycle); return 1; } } while (0)

int main(int argc, char **argv) {
    if (argc != 4) { fprintf(stderr, "usage: leak_host <TLD.so> <GUID> <cycles>\n"); return 2; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 2; }
    const char *guid = argv[2];
    int cycles = atoi(argv[3]);
    LOAD(fmi2Instantiate) LOAD(fmi2FreeInstance) LOAD(fmi2SetupExperiment)
    LOAD(fmi2EnterInitializationMode) LOAD(fmi2ExitInitializationMode) LOAD(fmi2Terminate)
    LOAD(fmi2SetReal) LOAD(fmi2GetReal) LOAD(fmi2DoStep) LOAD(fmi2GetFMUstate) LOAD(fmi2SetFMUstate)
    LOAD(fmi2FreeFMUstate) LOAD(fmi2SerializedFMUstateSize) LOAD(fmi2SerializeFMUstate)
    LOAD(fmi2DeSerializeFMUstate) LOAD(fmi2SetInteger)
    (void)fmi2SetInteger;
    callbacks_t cb = { logger, NULL, NULL, NULL, NULL };
    /* Value references from modelDescription.xml, passed in by scripts/leakcheck. */
    const unsigned base_a = VR_BASE_A, slosh_x = VR_SLOSH_X, eta = VR_ETA, unknown = 9999;
    double x = 0.0;
    int cycle;
    for (cycle = 0; cycle < cycles; cycle++) {
        comp_t c = fmi2Instantiate("leak", 1, guid, NULL, &cb, 0, 0);
        if (!c) { fprintf(stderr, "instantiate failed\n"); return 1; }
        CHECK(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
        CHECK(fmi2EnterInitializationMode(c), 0);
        double e = 2.5;
        CHECK(fmi2SetReal(c, &eta, 1, &e), 0);
#if defined(VR_CYCLE) && defined(CYCLE_N)
        const unsigned selector = VR_CYCLE;
        const int choice = 1 + cycle % CYCLE_N;
        CHECK(fmi2SetInteger(c, &selector, 1, &choice), 0);
#endif
#if defined(VR_EXTRA) && defined(EXTRA_VALUE)
        const unsigned extra = VR_EXTRA;
        const int extra_value = EXTRA_VALUE;
        CHECK(fmi2SetInteger(c, &extra, 1, &extra_value), 0);
#endif
        CHECK(fmi2ExitInitializationMode(c), 0);
        double t = 0.0, h = 0.01;
        void *state = NULL;
        for (int k = 0; k < 20; k++) {
            double a = -36.0 * 0.004 * sin(6.0 * t);
            CHECK(fmi2SetReal(c, &base_a, 1, &a), 0);
            CHECK(fmi2DoStep(c, t, h, 1), 0);
            t += h;
            if (k == 10) CHECK(fmi2GetFMUstate(c, &state), 0);
        }
        size_t n = 0;
        CHECK(fmi2SerializedFMUstateSize(c, state, &n), 0);
        char *bytes = malloc(n);
        CHECK(fmi2SerializeFMUstate(c, state, bytes, n), 0);
        void *copy = NULL;
        CHECK(fmi2DeSerializeFMUstate(c, bytes, n, &copy), 0);
        CHECK(fmi2DeSerializeFMUstate(c, bytes, n, &copy), 0); /* reuses `copy` */
        bytes[n / 2] ^= 1;
        void *bad = NULL;
        CHECK(fmi2DeSerializeFMUstate(c, bytes, n, &bad), 3);
        free(bytes);
        CHECK(fmi2SetFMUstate(c, copy), 0);
        CHECK(fmi2FreeFMUstate(c, &copy), 0);
        CHECK(fmi2FreeFMUstate(c, &state), 0);
        /* refused calls: logged, nothing kept */
        double nan = NAN;
        CHECK(fmi2SetReal(c, &base_a, 1, &nan), 3);
        CHECK(fmi2SetReal(c, &unknown, 1, &e), 3);
        CHECK(fmi2DoStep(c, t + 1.0, h, 1), 3);
        CHECK(fmi2GetReal(c, &slosh_x, 1, &x), 0);
        CHECK(fmi2Terminate(c), 0);
        fmi2FreeInstance(c);
    }
    printf("leak_host: %d cycles, %lu log messages, last slosh.x %.6e\n", cycles, messages, x);

    /* Heap held by one initialised instance: 1000 of them alive at once. */
    enum { LIVE = 1000 };
    static comp_t live[LIVE];
    struct mallinfo2 before = mallinfo2();
    for (int i = 0; i < LIVE; i++) {
        live[i] = fmi2Instantiate("live", 1, guid, NULL, &cb, 0, 0);
        cycle = i;
        CHECK(fmi2SetupExperiment(live[i], 0, 0.0, 0.0, 0, 0.0), 0);
        CHECK(fmi2EnterInitializationMode(live[i]), 0);
        CHECK(fmi2ExitInitializationMode(live[i]), 0);
        CHECK(fmi2DoStep(live[i], 0.0, 0.01, 1), 0);
    }
    struct mallinfo2 after = mallinfo2();
    printf("leak_host: heap per initialised instance: %zu bytes\n", (after.uordblks - before.uordblks) / LIVE);
    for (int i = 0; i < LIVE; i++) fmi2FreeInstance(live[i]);
    dlclose(lib);
    return 0;
}
