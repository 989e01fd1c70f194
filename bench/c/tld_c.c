/* A careful C FMU of the Nonlinear model: the benchmark's C anchor (issue #29), written from
 * MODEL.md for the benchmark and sharing no code with TLD.fmu. FMI 2.0 co-simulation, the same
 * value references as TLD.fmu's modelDescription.xml for what it models, so the benchmark's
 * native host drives it with the same calls (fmi2SetReal(base.a) + fmi2DoStep +
 * fmi2GetReal(slosh.x, slosh.v, force) per step).
 *
 *   x'' + 2 zeta w_f x' + Phi(x) = -a_b,   Phi(x) = w_f^2 x [1 + phi |2x/a|^(2 eta - 2)]
 *
 * with base.a held over each step, constant zeta (damping = Constant only), one sloshing mass
 * (the fundamental mode, Eq 2.1/2.2); integrated by RK4 with n = ceil(dt / solver.fixed_step)
 * equal substeps (solver = RK4) or Dormand-Prince 5(4) with error control at solver.tolerance
 * (solver = DormandPrince45, the default): the error norm of TLD.fmu (scales a/2 + |x| and
 * w_f a/2 + |v|), the step size carried from one communication step to the next. Careful: every
 * value a host sets is checked (finite, in range), a step that diverges is refused with the
 * state left as it was, and errors go to the host's logger.
 *
 * Build: gcc -O2 -shared -fPIC -o tld_c.so tld_c.c -lm   (bench/python/workprec/cfmu.py)
 *
 * With -DTLD_C_ENERGIES it also does what TLD.fmu must and this FMU otherwise leaves out: the
 * outputs energy.input and energy.dissipated, the integrals of the base's work -a_b x' and of
 * the dissipation c x'^2 per unit sloshing mass, integrated by the same method as x and v (two
 * more components of each stage, not error-controlled), so that a host can read them at any
 * communication point (bench/python/ab_settings.py times both builds).
 *
 * Parameters it does not model (NSD, amplitude, lambda, ...) are accepted and ignored; the
 * enumerations it does not implement (model other than Nonlinear, damping other than Constant,
 * other solvers) are refused at fmi2ExitInitializationMode. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef int fmi2Status;
enum { fmi2OK = 0, fmi2Warning = 1, fmi2Discard = 2, fmi2Error = 3, fmi2Fatal = 4 };
typedef void (*fmi2Logger)(void *env, const char *name, fmi2Status status, const char *category,
                           const char *message, ...);
typedef struct {
    fmi2Logger logger;
    void *allocate;
    void *freeMemory;
    void *stepFinished;
    void *componentEnvironment;
} fmi2CallbackFunctions;

/* TLD.fmu's value references (modelDescription/modelDescription.xml) */
enum {
    VR_LENGTH = 0, VR_BREADTH = 1, VR_DEPTH = 2, VR_DENSITY = 3, VR_G = 4, VR_TANKS = 5,
    VR_MODEL = 6, VR_ETA = 8, VR_PHI = 9, VR_DAMPING = 10, VR_ZETA = 11, VR_X0 = 19,
    VR_V0 = 20, VR_SOLVER = 21, VR_TOLERANCE = 22, VR_FIXED_STEP = 23, VR_MAX_SUBSTEPS = 25,
    VR_OMEGA_F = 40, VR_MASS_SLOSH = 42, VR_MASS_INACTIVE = 43, VR_BASE_A = 50, VR_FORCE = 60,
    VR_X = 63, VR_V = 64, VR_ENERGY_INPUT = 65, VR_ENERGY_DISSIPATED = 66
};
enum { MODEL_NONLINEAR = 2, DAMPING_CONSTANT = 1, SOLVER_DP45 = 1, SOLVER_RK4 = 2 };

typedef struct {
    /* parameters */
    double length, breadth, depth, density, g, eta, phi, zeta, x0, v0, tol, fixed_step;
    int tanks, model, damping, solver, max_substeps;
    /* derived at fmi2ExitInitializationMode */
    double w2, c, q, p, m, m0, omega, scale_x, scale_v;
    int p_int; /* p = 2 eta - 2 when an integer in [0, 64], else -1 */
    /* state */
    double x, v, a_b, h_carried;
    /* -DTLD_C_ENERGIES: the work in and the dissipation per unit sloshing mass, and the stored
     * energy at the start [J] (counted as input, as TLD.fmu does) */
    double w_in, w_diss, e0;
    int initialised;
    const fmi2CallbackFunctions *cb;
    char name[64];
} Tld;

static void say(Tld *s, fmi2Status status, const char *msg) {
    if (s->cb && s->cb->logger) s->cb->logger(s->cb->componentEnvironment, s->name, status,
                                                "logStatusError", "%s", msg);
}

static inline double ipow(double x, int n) {
    double r = 1.0;
    while (n) {
        if (n & 1) r *= x;
        x *= x;
        n >>= 1;
    }
    return r;
}

static inline double phi_of(const Tld *s, double x) {
    double ax = fabs(x);
    double h = s->p_int >= 0 ? (s->p_int == 2 ? ax * ax : ipow(ax, s->p_int)) : pow(ax, s->p);
    return s->w2 * x * (1.0 + s->q * h);
}

static inline double accel(const Tld *s, double x, double v, double ab) {
    return -ab - s->c * v - phi_of(s, x);
}

#ifdef TLD_C_ENERGIES
/* The energy integrands at velocity v: the base's work -a_b v and the dissipation c v^2. */
#define ENERGY_RATES(k, v) double k##w = -ab * (v), k##d = s->c * (v) * (v)
/* The stored energy [J]: kinetic plus the potential of Phi, m (v^2/2 + w2 x^2/2 [1 + q|x|^p/eta]). */
static double stored(const Tld *s, double x, double v) {
    double ax = fabs(x);
    double h = s->p_int >= 0 ? ipow(ax, s->p_int) : pow(ax, s->p);
    return s->m * (0.5 * v * v + 0.5 * s->w2 * x * x * (1.0 + s->q * h / s->eta));
}
#endif

fmi2Component fmi2Instantiate(const char *name, int type, const char *guid, const char *res,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible,
                              fmi2Boolean logging) {
    (void)type; (void)guid; (void)res; (void)visible; (void)logging;
    Tld *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->cb = cb;
    strncpy(s->name, name ? name : "tld_c", sizeof s->name - 1);
    /* TLD.fmu's defaults for what this FMU models */
    s->length = 0.25; s->breadth = 0.32; s->depth = 0.021; s->density = 1000.0; s->g = 9.81;
    s->tanks = 1; s->eta = 2.0; s->phi = 1.0; s->zeta = 0.01; s->tol = 1e-10;
    s->fixed_step = 1e-3; s->max_substeps = 100000;
    s->model = MODEL_NONLINEAR; s->damping = 2; s->solver = SOLVER_DP45;
    return s;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean td, fmi2Real tol, fmi2Real t0,
                               fmi2Boolean sd, fmi2Real t1) {
    (void)c; (void)td; (void)tol; (void)t0; (void)sd; (void)t1;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Tld *s = c;
    if (s->model != MODEL_NONLINEAR || s->damping != DAMPING_CONSTANT
        || (s->solver != SOLVER_DP45 && s->solver != SOLVER_RK4)) {
        say(s, fmi2Error, "only model = Nonlinear, damping = Constant, solver = "
                          "DormandPrince45 or RK4");
        return fmi2Error;
    }
    if (!(s->depth < s->length)) {
        say(s, fmi2Error, "tank.depth must be smaller than tank.length");
        return fmi2Error;
    }
    double r = s->depth / s->length, k = M_PI * r;
    s->omega = sqrt(s->g * M_PI * tanh(k) / s->length);
    double liquid = s->density * s->length * s->breadth * s->depth * s->tanks;
    s->m = liquid * 8.0 * tanh(k) / (M_PI * M_PI * M_PI * r);
    s->m0 = liquid - s->m;
    s->w2 = s->omega * s->omega;
    s->c = 2.0 * s->zeta * s->omega;
    s->p = 2.0 * s->eta - 2.0;
    s->p_int = (s->p == floor(s->p) && s->p <= 64.0) ? (int)s->p : -1;
    s->q = s->phi * pow(2.0 / s->length, s->p);
    s->scale_x = 0.5 * s->length;
    s->scale_v = 0.5 * s->length * s->omega;
    s->x = s->x0;
    s->v = s->v0;
    s->h_carried = 0.0;
#ifdef TLD_C_ENERGIES
    s->w_in = s->w_diss = 0.0;
    s->e0 = stored(s, s->x, s->v);
#endif
    s->initialised = 1;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { (void)c; return fmi2Error; }

static int set_real(Tld *s, fmi2ValueReference vr, double x) {
    if (!isfinite(x)) return 0;
    if (vr == VR_BASE_A) { s->a_b = x; return 1; }
    if (s->initialised) return 0; /* parameters are fixed */
    switch (vr) {
    case VR_LENGTH: if (!(x > 0)) return 0; s->length = x; return 1;
    case VR_BREADTH: if (!(x > 0)) return 0; s->breadth = x; return 1;
    case VR_DEPTH: if (!(x > 0)) return 0; s->depth = x; return 1;
    case VR_DENSITY: if (!(x > 0)) return 0; s->density = x; return 1;
    case VR_G: if (!(x > 0)) return 0; s->g = x; return 1;
    case VR_ETA: if (!(x >= 1 && x <= 10)) return 0; s->eta = x; return 1;
    case VR_PHI: if (!(x >= 0)) return 0; s->phi = x; return 1;
    case VR_ZETA: if (!(x >= 0 && x <= 1)) return 0; s->zeta = x; return 1;
    case VR_X0: s->x0 = x; return 1;
    case VR_V0: s->v0 = x; return 1;
    case VR_TOLERANCE: if (!(x >= 1e-14 && x <= 0.1)) return 0; s->tol = x; return 1;
    case VR_FIXED_STEP: if (!(x >= 1e-9)) return 0; s->fixed_step = x; return 1;
    default: return vr < VR_BASE_A; /* parameters it does not model */
    }
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                       const fmi2Real value[]) {
    Tld *s = c;
    if (n && (!vr || !value)) return fmi2Error;
    for (size_t i = 0; i < n; i++)
        if (!set_real(s, vr[i], value[i])) {
            say(s, fmi2Error, "fmi2SetReal: a value out of range, not finite or not settable");
            return fmi2Error;
        }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer value[]) {
    Tld *s = c;
    if (s->initialised || (n && (!vr || !value))) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_TANKS: if (value[i] < 1) return fmi2Error; s->tanks = value[i]; break;
        case VR_MODEL: s->model = value[i]; break;
        case VR_DAMPING: s->damping = value[i]; break;
        case VR_SOLVER: s->solver = value[i]; break;
        case VR_MAX_SUBSTEPS: if (value[i] < 1) return fmi2Error; s->max_substeps = value[i]; break;
        default: if (vr[i] >= VR_BASE_A) return fmi2Error; /* others: not modelled */
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                          const fmi2Boolean value[]) {
    (void)c; (void)vr; (void)value;
    return n ? fmi2Error : fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                       fmi2Real value[]) {
    Tld *s = c;
    if (n && (!vr || !value)) return fmi2Error;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case VR_X: value[i] = s->x; break;
        case VR_V: value[i] = s->v; break;
        case VR_FORCE: value[i] = s->m * (s->c * s->v + phi_of(s, s->x)); break;
        case VR_MASS_INACTIVE: value[i] = s->m0; break;
        case VR_MASS_SLOSH: value[i] = s->m; break;
        case VR_OMEGA_F: value[i] = s->omega; break;
        case VR_BASE_A: value[i] = s->a_b; break;
#ifdef TLD_C_ENERGIES
        case VR_ENERGY_INPUT: value[i] = s->e0 + s->m * s->w_in; break;
        case VR_ENERGY_DISSIPATED: value[i] = s->m * s->w_diss; break;
#endif
        default: say(s, fmi2Error, "fmi2GetReal: unknown value reference"); return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)c; (void)vr; (void)order; (void)value;
    return n ? fmi2Error : fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t n, const fmi2Integer order[], fmi2Real value[]) {
    (void)c; (void)vr; (void)order; (void)value;
    return n ? fmi2Error : fmi2OK;
}

/* RK4 with n equal substeps over dt; 0 on success. pe: the energy integrals (-DTLD_C_ENERGIES). */
static int rk4(const Tld *s, double dt, double *px, double *pv, double *pe) {
    double q = dt / s->fixed_step * (1.0 - 1e-12);
    if (!(q <= s->max_substeps)) return -1;
    int n = (int)q;
    if (n < q || n == 0) n++;
    double h = dt / n, x = *px, v = *pv, ab = s->a_b;
#ifdef TLD_C_ENERGIES
    double w = pe[0], d = pe[1];
#else
    (void)pe;
#endif
    for (int i = 0; i < n; i++) {
        double k1x = v, k1v = accel(s, x, v, ab);
        double x2 = x + 0.5 * h * k1x, v2 = v + 0.5 * h * k1v;
        double k2x = v2, k2v = accel(s, x2, v2, ab);
        double x3 = x + 0.5 * h * k2x, v3 = v + 0.5 * h * k2v;
        double k3x = v3, k3v = accel(s, x3, v3, ab);
        double x4 = x + h * k3x, v4 = v + h * k3v;
        double k4x = v4, k4v = accel(s, x4, v4, ab);
#ifdef TLD_C_ENERGIES
        ENERGY_RATES(k1, v); ENERGY_RATES(k2, v2); ENERGY_RATES(k3, v3); ENERGY_RATES(k4, v4);
        w += h / 6.0 * (k1w + 2.0 * (k2w + k3w) + k4w);
        d += h / 6.0 * (k1d + 2.0 * (k2d + k3d) + k4d);
#endif
        x += h / 6.0 * (k1x + 2.0 * (k2x + k3x) + k4x);
        v += h / 6.0 * (k1v + 2.0 * (k2v + k3v) + k4v);
    }
    *px = x;
    *pv = v;
#ifdef TLD_C_ENERGIES
    pe[0] = w;
    pe[1] = d;
#endif
    return 0;
}

/* Dormand & Prince (1980) 5(4), error per step against the mixed scales; 0 on success. */
static int dp45(Tld *s, double dt, double *px, double *pv, double *pe) {
    static const double a21 = 1.0 / 5.0, a31 = 3.0 / 40.0, a32 = 9.0 / 40.0,
        a41 = 44.0 / 45.0, a42 = -56.0 / 15.0, a43 = 32.0 / 9.0, a51 = 19372.0 / 6561.0,
        a52 = -25360.0 / 2187.0, a53 = 64448.0 / 6561.0, a54 = -212.0 / 729.0,
        a61 = 9017.0 / 3168.0, a62 = -355.0 / 33.0, a63 = 46732.0 / 5247.0, a64 = 49.0 / 176.0,
        a65 = -5103.0 / 18656.0, b1 = 35.0 / 384.0, b3 = 500.0 / 1113.0, b4 = 125.0 / 192.0,
        b5 = -2187.0 / 6784.0, b6 = 11.0 / 84.0, e1 = 71.0 / 57600.0, e3 = -71.0 / 16695.0,
        e4 = 71.0 / 1920.0, e5 = -17253.0 / 339200.0, e6 = 22.0 / 525.0, e7 = -1.0 / 40.0;
    double x = *px, v = *pv, ab = s->a_b, t = 0.0;
#ifdef TLD_C_ENERGIES
    double w = pe[0], d = pe[1];
#else
    (void)pe;
#endif
    double h = s->h_carried > 0 ? s->h_carried : fmin(0.5 * pow(s->tol, 0.2) / s->omega, dt);
    double k1x = v, k1v = accel(s, x, v, ab);
    int rejected = 0;
    for (int steps = 1;; steps++) {
        if (steps > s->max_substeps) return -1;
        double rem = dt - t;
        int last = h >= rem;
        double hs = last ? rem : h;
        double y2x = x + hs * a21 * k1x, y2v = v + hs * a21 * k1v;
        double k2x = y2v, k2v = accel(s, y2x, y2v, ab);
        double y3x = x + hs * (a31 * k1x + a32 * k2x), y3v = v + hs * (a31 * k1v + a32 * k2v);
        double k3x = y3v, k3v = accel(s, y3x, y3v, ab);
        double y4x = x + hs * (a41 * k1x + a42 * k2x + a43 * k3x);
        double y4v = v + hs * (a41 * k1v + a42 * k2v + a43 * k3v);
        double k4x = y4v, k4v = accel(s, y4x, y4v, ab);
        double y5x = x + hs * (a51 * k1x + a52 * k2x + a53 * k3x + a54 * k4x);
        double y5v = v + hs * (a51 * k1v + a52 * k2v + a53 * k3v + a54 * k4v);
        double k5x = y5v, k5v = accel(s, y5x, y5v, ab);
        double y6x = x + hs * (a61 * k1x + a62 * k2x + a63 * k3x + a64 * k4x + a65 * k5x);
        double y6v = v + hs * (a61 * k1v + a62 * k2v + a63 * k3v + a64 * k4v + a65 * k5v);
        double k6x = y6v, k6v = accel(s, y6x, y6v, ab);
        double xn = x + hs * (b1 * k1x + b3 * k3x + b4 * k4x + b5 * k5x + b6 * k6x);
        double vn = v + hs * (b1 * k1v + b3 * k3v + b4 * k4v + b5 * k5v + b6 * k6v);
        double k7x = vn, k7v = accel(s, xn, vn, ab);
        double ex = hs * (e1 * k1x + e3 * k3x + e4 * k4x + e5 * k5x + e6 * k6x + e7 * k7x);
        double ev = hs * (e1 * k1v + e3 * k3v + e4 * k4v + e5 * k5v + e6 * k6v + e7 * k7v);
        double sx = s->tol * (s->scale_x + fmax(fabs(x), fabs(xn)));
        double sv = s->tol * (s->scale_v + fmax(fabs(v), fabs(vn)));
        double err = sqrt(0.5 * ((ex / sx) * (ex / sx) + (ev / sv) * (ev / sv)));
        if (err <= 1.0) {
            double fac = err == 0.0 ? 5.0 : fmin(fmax(0.9 * pow(err, -0.2), 0.2), 5.0);
            if (rejected) fac = fmin(fac, 1.0);
            rejected = 0;
#ifdef TLD_C_ENERGIES
            /* the energies' stages: the integrands at the stage velocities (k_i x = v_i) */
            ENERGY_RATES(q1, k1x); ENERGY_RATES(q3, k3x); ENERGY_RATES(q4, k4x);
            ENERGY_RATES(q5, k5x); ENERGY_RATES(q6, k6x);
            w += hs * (b1 * q1w + b3 * q3w + b4 * q4w + b5 * q5w + b6 * q6w);
            d += hs * (b1 * q1d + b3 * q3d + b4 * q4d + b5 * q5d + b6 * q6d);
#endif
            x = xn; v = vn; k1x = k7x; k1v = k7v;
            double proposal = hs * fac;
            if (last) {
                /* a step shortened to land on the communication point does not set the pace */
                s->h_carried = hs < h ? fmax(h, proposal) : proposal;
                break;
            }
            t += hs;
            h = proposal;
        } else {
            rejected = 1;
            h = hs * (isfinite(err) ? fmin(fmax(0.9 * pow(err, -0.2), 0.2), 1.0) : 0.25);
            if (h < 1e-14 * dt) return -1;
        }
    }
    *px = x;
    *pv = v;
#ifdef TLD_C_ENERGIES
    pe[0] = w;
    pe[1] = d;
#endif
    return 0;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real dt, fmi2Boolean noSetPrior) {
    Tld *s = c;
    (void)noSetPrior;
    if (!s->initialised || !(dt > 0) || !isfinite(t) || !isfinite(dt)) {
        say(s, fmi2Error, "fmi2DoStep: not initialised, or a bad time or step");
        return fmi2Error;
    }
    double x = s->x, v = s->v, carried = s->h_carried;
    double e[2] = {s->w_in, s->w_diss};
    int fail = s->solver == SOLVER_RK4 ? rk4(s, dt, &x, &v, e) : dp45(s, dt, &x, &v, e);
    if (fail || !isfinite(x) || !isfinite(v) || fabs(x) > 100.0 * s->length) {
        s->h_carried = carried; /* all or nothing */
        say(s, fmi2Discard, "fmi2DoStep: the step failed (too many substeps or a runaway); "
                            "the state is left at the start of the step");
        return fmi2Discard;
    }
    s->x = x;
    s->v = v;
#ifdef TLD_C_ENERGIES
    s->w_in = e[0];
    s->w_diss = e[1];
#endif
    return fmi2OK;
}
