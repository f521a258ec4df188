"""Timing helpers shared by the peer benchmark scripts: median and best of repeated calls after
one warm-up, printed in one aligned line per case."""
import statistics
import time


def timed(fn, repeats):
    """(median, min) wall seconds of `repeats` calls of fn(), after one untimed warm-up call."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times)


def report(name, med_min, width=58):
    med, best = med_min
    print(f"{name:<{width}s} median {med * 1e3:10.2f} ms   min {best * 1e3:10.2f} ms", flush=True)
