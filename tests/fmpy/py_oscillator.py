"""A small co-simulation slave in plain Python, packaged as an FMU with pythonfmu (PyPI) by
make_pythonfmu.py: a damped oscillator driven by an input force, plus a sine signal generator,
a step counter (Integer) and a moving flag (Boolean), so the host exchanges all three
scalar types.

Physics: m x'' = -k x - d x' + force + amplitude * sin(2 pi frequency t), integrated with 10
classical RK4 sub-steps per communication step, the force held over the step.
"""
import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Boolean, Integer, Real


class PyOscillator(Fmi2Slave):

    author = "rail-fmu project (test FMU)"
    description = "Damped oscillator with an input force and a sine drive, written in Python"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.mass = 1.0
        self.stiffness = 40.0
        self.damping = 0.3
        self.amplitude = 2.0
        self.frequency = 1.5
        self.initial_position = 0.05
        self.force = 0.0
        self.position = 0.05
        self.velocity = 0.0
        self.drive = 0.0
        self.steps = 0
        self.moving_right = False
        fixed = dict(causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed)
        for p in ("mass", "stiffness", "damping", "amplitude", "frequency", "initial_position"):
            self.register_variable(Real(p, **fixed))
        self.register_variable(Real("force", causality=Fmi2Causality.input))
        for o in ("position", "velocity", "drive"):
            self.register_variable(Real(o, causality=Fmi2Causality.output))
        self.register_variable(Integer("steps", causality=Fmi2Causality.output, variability=Fmi2Variability.discrete))
        self.register_variable(Boolean("moving_right", causality=Fmi2Causality.output, variability=Fmi2Variability.discrete))

    def exit_initialization_mode(self):
        self.position = self.initial_position
        self.velocity = 0.0

    def _acc(self, t, x, v):
        drive = self.amplitude * math.sin(2.0 * math.pi * self.frequency * t)
        return (-self.stiffness * x - self.damping * v + self.force + drive) / self.mass

    def do_step(self, current_time, step_size):
        n = 10
        h = step_size / n
        x, v = self.position, self.velocity
        for i in range(n):
            t = current_time + i * h
            k1x, k1v = v, self._acc(t, x, v)
            k2x, k2v = v + 0.5 * h * k1v, self._acc(t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v)
            k3x, k3v = v + 0.5 * h * k2v, self._acc(t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v)
            k4x, k4v = v + h * k3v, self._acc(t + h, x + h * k3x, v + h * k3v)
            x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
        self.position, self.velocity = x, v
        t_end = current_time + step_size
        self.drive = self.amplitude * math.sin(2.0 * math.pi * self.frequency * t_end)
        self.steps += 1
        self.moving_right = v > 0.0
        return True
