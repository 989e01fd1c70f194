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
 * With -DNX=n (the model description's continuous states), cycles also run a Model
 * Exchange instance of the same configuration (every configuration, one round in 50;
 * -DVR_AMPLITUDE=vr: amplitude = Fixed and Tracked, whose samples are time events, in
 * alternate ME rounds): the event iteration, the time events, continuous-time mode, states
 * and derivatives, a refused non-finite state, a saved and restored state; a configuration ME
 * does not offer is refused at exit (fmi2Error) and freed.
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
#ifdef NX
    typedef int (*fmi2SetTime_t)(comp_t, double);
    typedef int (*fmi2States_t)(comp_t, double *, size_t);
    typedef int (*fmi2SetContinuousStates_t)(comp_t, const double *, size_t);
    typedef int (*fmi2Mode_t)(comp_t);
    typedef int (*fmi2CompletedIntegratorStep_t)(comp_t, int, int *, int *);
    typedef struct { int needed, terminate, nominals, values, next_defined; double next; } info_t;
    typedef int (*fmi2NewDiscreteStates_t)(comp_t, info_t *);
    fmi2SetTime_t fmi2SetTime = (fmi2SetTime_t)dlsym(lib, "fmi2SetTime");
    fmi2States_t fmi2GetContinuousStates = (fmi2States_t)dlsym(lib, "fmi2GetContinuousStates");
    fmi2States_t fmi2GetDerivatives = (fmi2States_t)dlsym(lib, "fmi2GetDerivatives");
    fmi2SetContinuousStates_t fmi2SetContinuousStates =
        (fmi2SetContinuousStates_t)dlsym(lib, "fmi2SetContinuousStates");
    fmi2Mode_t fmi2EnterContinuousTimeMode = (fmi2Mode_t)dlsym(lib, "fmi2EnterContinuousTimeMode");
    fmi2Mode_t fmi2EnterEventMode = (fmi2Mode_t)dlsym(lib, "fmi2EnterEventMode");
    fmi2CompletedIntegratorStep_t fmi2CompletedIntegratorStep =
        (fmi2CompletedIntegratorStep_t)dlsym(lib, "fmi2CompletedIntegratorStep");
    fmi2NewDiscreteStates_t fmi2NewDiscreteStates =
        (fmi2NewDiscreteStates_t)dlsym(lib, "fmi2NewDiscreteStates");
    if (!fmi2SetTime || !fmi2GetContinuousStates || !fmi2GetDerivatives || !fmi2SetContinuousStates
        || !fmi2EnterContinuousTimeMode || !fmi2CompletedIntegratorStep || !fmi2NewDiscreteStates
        || !fmi2EnterEventMode) {
        fprintf(stderr, "missing a Model Exchange function\n");
        return 2;
    }
    unsigned long me_runs = 0, time_events = 0;
#endif
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
#ifdef NX
        /* Every configuration in turn, one round in 50 (valgrind makes an ME run of 20 steps
         * of the 44-state building cost about 0.1 s). */
#if defined(VR_CYCLE) && defined(CYCLE_N)
        const unsigned long me_turn = (unsigned long)cycle / CYCLE_N;
#else
        const unsigned long me_turn = (unsigned long)cycle;
#endif
        const int me_round = me_turn % 50 == 0;
        if (!me_round) continue;
        comp_t m = fmi2Instantiate("leak-me", 0, guid, NULL, &cb, 0, 0);
        if (!m) { fprintf(stderr, "instantiate (Model Exchange) failed\n"); return 1; }
        CHECK(fmi2SetupExperiment(m, 0, 0.0, 0.0, 0, 0.0), 0);
        CHECK(fmi2EnterInitializationMode(m), 0);
#if defined(VR_CYCLE) && defined(CYCLE_N)
        CHECK(fmi2SetInteger(m, &selector, 1, &choice), 0);
#endif
#if defined(VR_EXTRA) && defined(EXTRA_VALUE)
        CHECK(fmi2SetInteger(m, &extra, 1, &extra_value), 0);
#endif
#ifdef VR_AMPLITUDE
        const unsigned amplitude = VR_AMPLITUDE;
        const int source = 1 + (int)(me_turn / 50 % 2);
        CHECK(fmi2SetInteger(m, &amplitude, 1, &source), 0);
#endif
        if (fmi2ExitInitializationMode(m) == 0) {
            info_t info;
            double xs[NX], dx[NX], tm = 0.0;
            CHECK(fmi2NewDiscreteStates(m, &info), 0);
            CHECK(fmi2EnterContinuousTimeMode(m), 0);
            CHECK(fmi2GetContinuousStates(m, xs, NX), 0);
            void *saved = NULL;
            for (int k = 0; k < 20; k++) {
                double a = -36.0 * 0.004 * sin(6.0 * tm);
                CHECK(fmi2SetReal(m, &base_a, 1, &a), 0);
                CHECK(fmi2GetDerivatives(m, dx, NX), 0);
                for (int i = 0; i < NX; i++) xs[i] += 0.01 * dx[i];
                tm += 0.01;
                CHECK(fmi2SetTime(m, tm), 0);
                CHECK(fmi2SetContinuousStates(m, xs, NX), 0);
                int enter = 0, stop = 0;
                CHECK(fmi2CompletedIntegratorStep(m, 1, &enter, &stop), 0);
                if (info.next_defined && tm >= info.next) {
                    CHECK(fmi2EnterEventMode(m), 0);
                    CHECK(fmi2NewDiscreteStates(m, &info), 0);
                    CHECK(fmi2EnterContinuousTimeMode(m), 0);
                    time_events++;
                }
                if (k == 10) CHECK(fmi2GetFMUstate(m, &saved), 0);
            }
            double bad_states[NX];
            memcpy(bad_states, xs, sizeof xs);
            bad_states[0] = NAN;
            CHECK(fmi2SetContinuousStates(m, bad_states, NX), 3);
            CHECK(fmi2SetFMUstate(m, saved), 0);
            CHECK(fmi2FreeFMUstate(m, &saved), 0);
            CHECK(fmi2Terminate(m), 0);
            me_runs++;
        }
        fmi2FreeInstance(m);
#endif
    }
    printf("leak_host: %d cycles, %lu log messages, last slosh.x %.6e\n", cycles, messages, x);
#ifdef NX
    printf("leak_host: %lu of them ran Model Exchange (%d states), %lu time events\n", me_runs, NX,
           time_events);
    if (cycles > 0 && me_runs == 0) { fprintf(stderr, "no cycle ran Model Exchange\n"); return 1; }
#endif

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
