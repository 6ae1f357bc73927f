"""Times a third-party C++ co-simulation host running an SSP, for the benchmark
tests/benches/ratios/ (section `peers`).

    bench_hosts.py HOST SYSTEM.ssp STOP_TIME STEP REPEATS INSTANCE.VARIABLE

HOST is libcosim (libcosimpy: CosimExecution.from_ssp_file, then simulate_until, the SSP's own
osp:FixedStepAlgorithm step, which the master's export sets to the system's) or ecos (ecospy:
EcosSimulation(ssp_path=..., step_size=STEP), init with the parameter sets' name, then
step_until). Each repeat builds a new execution (loading the FMUs is
not timed) and times the host's own run-until call alone, so no Python runs between the steps.

Prints `wall_per_sim_s`, `cpu_per_sim_s` (this process's user + system time over the call: a
host that steps the FMUs on worker threads uses more CPU than wall time) of the fastest repeat,
and `final` (INSTANCE.VARIABLE after the last step, to check the run against the master's).
Exit status 0 on success; any host error is printed and gives 1.
"""

import resource
import sys
import time
import zipfile


def cpu_s():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def run_libcosim(ssp, stop, instance, variable):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    # libcosim warns that it ignores FMI 2.0 Enumeration variables (their defaults stand)
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(ssp_path=ssp)
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    index = ex.slave_index_from_instance_name(instance)
    refs = [v.reference for v in ex.slave_variables(index) if v.name.decode() == variable]
    if not refs:
        raise SystemExit(f"libcosim: no variable {variable} in {instance}")
    t0, c0 = time.perf_counter(), cpu_s()
    if not ex.simulate_until(target_time=int(round(stop * 1e9))):
        raise SystemExit("libcosim: simulate_until failed")
    wall, cpu = time.perf_counter() - t0, cpu_s() - c0
    final = observer.last_real_values(slave_index=index, variable_references=refs)[0]
    return wall, cpu, final


def parameter_set_name(ssp):
    with zipfile.ZipFile(ssp) as z:
        for name in z.namelist():
            if name.endswith(".ssv"):
                text = z.read(name).decode()
                start = text.find('name="')
                if start >= 0:
                    return text[start + 6:text.find('"', start + 6)]
    return None


def run_ecos(ssp, stop, instance, variable, step):
    from ecospy import EcosSimulation

    sim = EcosSimulation(ssp_path=ssp, step_size=step)
    name = parameter_set_name(ssp)
    # Ecos applies the SSP's parameter sets only when told their name
    if name is None:
        sim.init()
    else:
        sim.init(parameter_set=name)
    t0, c0 = time.perf_counter(), cpu_s()
    sim.step_until(stop)
    wall, cpu = time.perf_counter() - t0, cpu_s() - c0
    final = sim.get_real(f"{instance}::{variable}")
    sim.terminate()
    return wall, cpu, final


def main():
    if len(sys.argv) != 7:
        raise SystemExit(__doc__)
    host, ssp, stop, step, repeats, target = sys.argv[1:]
    stop, step, repeats = float(stop), float(step), int(repeats)
    instance, variable = target.split(".", 1)
    runs = []
    for _ in range(repeats):
        if host == "libcosim":
            runs.append(run_libcosim(ssp, stop, instance, variable))
        elif host == "ecos":
            runs.append(run_ecos(ssp, stop, instance, variable, step))
        else:
            raise SystemExit(f"unknown host {host} (libcosim or ecos)")
    wall, cpu, final = min(runs, key=lambda r: r[0])
    print(f"wall_per_sim_s {wall / stop:.9e}")
    print(f"cpu_per_sim_s {cpu / stop:.9e}")
    print(f"final {final!r}")


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception as e:  # any host error: one line and exit status 1
        print(f"{type(e).__name__}: {e}", file=sys.stderr)
        sys.exit(1)
