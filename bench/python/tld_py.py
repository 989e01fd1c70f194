"""The TLD model of the benchmark as a Python FMU (pythonfmu): the peer a Python user would write.

Same equations as TLD.fmu's Nonlinear model with a constant damping ratio (Eq 2.11 with the
power law Phi of Eq 2.13), base acceleration held over each communication step, classical RK4
with equal substeps no longer than `fixed_step`. Geometry (omega_f, sloshing mass) from Eqs 2.1/2.2.
Built by `pythonfmu build -f tld_py.py` (bench/python/workprec/baselines.py does it).
"""
import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class TLDPy(Fmi2Slave):
    author = "tld-fmu benchmark"
    description = "Nonlinear TLD (Eq 2.11/2.13), constant damping, RK4 substeps, in Python"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.tank_length = 0.25
        self.tank_breadth = 0.32
        self.tank_depth = 0.021
        self.density = 1000.0
        self.g = 9.81
        self.eta = 2.0
        self.phi = 1.0
        self.zeta = 0.01
        self.fixed_step = 0.001
        self.x0 = 0.0
        self.v0 = 0.0
        self.base_a = 0.0
        self.slosh_x = 0.0
        self.slosh_v = 0.0
        self.force = 0.0
        self._ready = False
        par = dict(causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed)
        for name in ("tank_length", "tank_breadth", "tank_depth", "density", "g", "eta", "phi",
                     "zeta", "fixed_step", "x0", "v0"):
            self.register_variable(Real(name, **par))
        self.register_variable(Real("base_a", causality=Fmi2Causality.input))
        for name in ("slosh_x", "slosh_v", "force"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))

    def _setup(self):
        a, h = self.tank_length, self.tank_depth
        r = h / a
        m_l = self.density * a * self.tank_breadth * h
        self._m = m_l * 8.0 * math.tanh(math.pi * r) / (math.pi ** 3 * r)
        w = math.sqrt(self.g * math.pi * math.tanh(math.pi * r) / a)
        self._w2 = w * w
        self._c = 2.0 * self.zeta * w
        self._q = self.phi * (2.0 / a) ** (2.0 * self.eta - 2.0)
        self._p = 2.0 * self.eta - 2.0
        self._x, self._v = float(self.x0), float(self.v0)
        self._ready = True
        self._outputs()

    def _outputs(self):
        x, v = self._x, self._v
        self.slosh_x, self.slosh_v = x, v
        self.force = self._m * (self._c * v + self._w2 * x * (1.0 + self._q * abs(x) ** self._p))

    def exit_initialization_mode(self):
        self._setup()

    def do_step(self, current_time, step_size):
        if not self._ready:
            self._setup()
        n = max(1, math.ceil(step_size / self.fixed_step - 1e-9))
        h = step_size / n
        ab, c, w2, q, p = self.base_a, self._c, self._w2, self._q, self._p
        x, v = self._x, self._v

        def acc(x, v):
            return -ab - c * v - w2 * x * (1.0 + q * abs(x) ** p)

        for _ in range(n):
            k1x, k1v = v, acc(x, v)
            x2, v2 = x + 0.5 * h * k1x, v + 0.5 * h * k1v
            k2x, k2v = v2, acc(x2, v2)
            x3, v3 = x + 0.5 * h * k2x, v + 0.5 * h * k2v
            k3x, k3v = v3, acc(x3, v3)
            x4, v4 = x + h * k3x, v + h * k3v
            k4x, k4v = v4, acc(x4, v4)
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
        self._x, self._v = x, v
        self._outputs()
        return True
