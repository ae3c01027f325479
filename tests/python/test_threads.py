# SPDX-License-Identifier: BSD-3-Clause
"""One File used from several threads: a call that finds another running on the same File
raises RuntimeError (BUSY) at once, close() included, and nothing crashes. Deterministic
cases hold a call open (inside the library's full extraction, or in an on_step callback) and
try every other call meanwhile; a bounded hammer mixes full and progressive extractions,
extract_steps(), cache_mb changes and close() on several threads and accepts only the
documented exceptions; Files of their own, one per thread, run side by side."""
import random
import threading
import time
import unittest

import support  # first: it skips (status 77) when numpy is absent
import numpy as np
import isoprop
from isoprop import volume

ISO = 1000.5
SIZE = (32, 24)
BUSY = "isoprop.File: another call is running on this File (one thread at a time)"
# what a call may raise in the hammer besides BUSY: the file closed by another thread (before
# the call, or between the steps of an extract_steps() run), and another cache_mb while an
# extract_steps() run of another thread is open
DOCUMENTED = ("the file is closed", "the file was closed during the extraction",
              "cache_mb cannot change while an extract_steps() run is open")


class Threads(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.ibv = support.phantom((48, 40, 36), "uint16", "1,1,1.5")
        with isoprop.open(cls.ibv) as f:
            cls.full = f.extract(ISO, full=True, threads=1)
            cls.progressive = f.extract(ISO, size=SIZE, threads=1)

    def assert_busy(self, call):
        with self.assertRaises(RuntimeError) as caught:
            call()
        self.assertEqual(str(caught.exception), BUSY)

    def other_calls(self, f):
        """Every call on f, each of which must be refused while another runs."""
        return {
            "extract full": lambda: f.extract(ISO, full=True, threads=1),
            "extract full lod": lambda: f.extract(ISO, full="lod", size=SIZE),
            "extract progressive": lambda: f.extract(ISO, size=SIZE, threads=1),
            "extract_steps": lambda: next(f.extract_steps(ISO, size=SIZE, rays_per_step=8)),
            "cache_mb change": lambda: f.extract(ISO, size=SIZE, rays=1, cache_mb=17),
            "close": f.close,
        }

    def test_calls_during_a_full_extraction_are_refused(self):
        """A thread held inside ip_extract_full() (the library call releases the GIL): every
        other call raises BUSY; the held call then finishes with the right mesh."""
        entered, go = threading.Event(), threading.Event()
        original = volume.lib.ip_extract_full

        def held(*args):
            entered.set()
            go.wait(60)
            return original(*args)

        f = isoprop.open(self.ibv)
        steps = f.extract_steps(ISO, size=SIZE, rays_per_step=8)
        first = next(steps)  # a run open between its steps, resumed below
        out = {}
        volume.lib.ip_extract_full = held
        try:
            worker = threading.Thread(
                target=lambda: out.update(mesh=f.extract(ISO, full=True, threads=1)))
            worker.start()
            self.assertTrue(entered.wait(60))
            for name, call in self.other_calls(f).items():
                with self.subTest(call=name):
                    self.assert_busy(call)
            self.assert_busy(lambda: next(steps))
            self.assertIsNotNone(f.camera(size=SIZE))  # touches no library state: allowed
        finally:
            go.set()
            volume.lib.ip_extract_full = original
            worker.join(60)
        np.testing.assert_array_equal(out["mesh"].vertices, self.full.vertices)
        self.assertEqual(first.rays, 8)
        # the step refused above ended that generator; its engine was freed by the next call
        self.assertEqual(list(steps), [])
        self.assertFalse(f._runs)
        self.assertFalse(f._orphans)
        f.close()
        with self.assertRaises(ValueError):
            f.extract(ISO, full=True)

    def test_calls_from_on_step_are_refused(self):
        """on_step runs inside its extract() call: calling the File from it (on the same
        thread, or another) raises BUSY rather than deadlock; the run completes."""
        f = isoprop.open(self.ibv)
        seen = []

        def on_step(step):
            if not seen:
                for name, call in self.other_calls(f).items():
                    with self.subTest(call=name):
                        self.assert_busy(call)
                refused = []

                def from_another_thread():
                    try:
                        f.close()
                    except RuntimeError as e:
                        refused.append(str(e))

                t = threading.Thread(target=from_another_thread)
                t.start()
                t.join(60)
                self.assertEqual(refused, [BUSY])
            seen.append(step.rays)

        mesh = f.extract(ISO, size=SIZE, threads=1, on_step=on_step)
        np.testing.assert_array_equal(mesh.vertices, self.progressive.vertices)
        self.assertEqual(seen[:3], [1, 2, 4])
        f.close()

    def test_close_between_steps_of_another_thread(self):
        """close() while an extract_steps() run is open (not running) frees it; the run's next
        step says the file was closed."""
        f = isoprop.open(self.ibv)
        steps = f.extract_steps(ISO, size=SIZE, rays_per_step=8)
        next(steps)
        t = threading.Thread(target=f.close)
        t.start()
        t.join(60)
        with self.assertRaises(ValueError) as caught:
            next(steps)
        self.assertIn("closed during the extraction", str(caught.exception))

    def test_one_file_per_thread(self):
        """Files of the same brick file, one per thread, run at once without refusals."""
        out = {}

        def work(k):
            with isoprop.open(self.ibv) as f:
                for _ in range(3):
                    out[k] = (f.extract(ISO, full=True, threads=1),
                              f.extract(ISO, size=SIZE, threads=1))

        self.assertEqual(support.run_threads(work, 3), [])
        for full, progressive in out.values():
            np.testing.assert_array_equal(full.vertices, self.full.vertices)
            np.testing.assert_array_equal(progressive.vertices, self.progressive.vertices)

    def test_bricks_side_by_side(self):
        """brick() on several threads at once, each of its own array-like (sliced on the
        bricker's reading thread, under the GIL) into its own output: every file equals the
        one brick() makes alone; and an array-like whose slicing raises on one thread fails
        only that thread's run."""
        shape = (36, 40, 48)
        arrays = [np.random.default_rng(k).integers(0, 4000, shape, dtype=np.uint16)
                  for k in range(3)]
        alone = []
        for k, a in enumerate(arrays):
            path = support.work("alone-%d.ibv" % k)
            isoprop.brick(a, path, brick_size=8, threads=2)
            with open(path, "rb") as f:
                alone.append(f.read())

        class Sliced:
            def __init__(self, a, fail):
                self.a, self.fail, self.shape, self.dtype = a, fail, a.shape, a.dtype

            def __getitem__(self, key):
                if self.fail and key.start > 8:
                    raise LookupError("no planes past 8")
                return self.a[key]

        results = {}

        def work(k):
            path = support.work("side-%d.ibv" % k)
            try:
                for _ in range(2):
                    isoprop.brick(Sliced(arrays[k % 3], k == 3), path, brick_size=8,
                                  threads=2, force=True)
            except LookupError as e:
                results[k] = e
                return
            with open(path, "rb") as f:
                results[k] = f.read()

        self.assertEqual(support.run_threads(work, 4), [])
        for k in range(3):
            self.assertEqual(results[k], alone[k], "brick file %d differs" % k)
        self.assertIsInstance(results[3], LookupError)

    def test_hammer(self):
        """Threads share one File: full (level 0 and lod) and progressive extractions,
        extract_steps() left after a few steps, cache_mb changes, the camera, and close() by
        one of them part way; several rounds. No crash, only BUSY and the documented
        ValueErrors, and every mesh that comes back is right."""
        threads, iterations, rounds = 4, 30, 3
        tally = {"ok": 0, "busy": 0, "documented": 0, "close refused": 0}
        lock = threading.Lock()
        failures = []

        def count(key):
            with lock:
                tally[key] += 1

        def hammer(f, seed, closer):
            rng = random.Random(seed)
            close_at = rng.randrange(iterations // 2, iterations) if closer else None
            for i in range(iterations):
                op = rng.randrange(7)
                try:
                    if i == close_at:
                        while True:  # close() is refused while another call runs: retry
                            try:
                                f.close()
                                break
                            except RuntimeError as e:
                                if type(e) is not RuntimeError or str(e) != BUSY:
                                    raise
                                count("close refused")
                                time.sleep(0.001)
                    elif op == 0:
                        mesh = f.extract(ISO, full=True, threads=rng.choice((1, 2)))
                        if not np.array_equal(mesh.vertices, self.full.vertices):
                            raise AssertionError("a full extraction gave other triangles")
                    elif op == 1:
                        f.extract(ISO, full="lod", size=SIZE, threads=1)
                    elif op == 2:
                        mesh = f.extract(ISO, size=SIZE, threads=1)
                        if not np.array_equal(mesh.vertices, self.progressive.vertices):
                            raise AssertionError("a progressive extraction gave other triangles")
                    elif op == 3:
                        for k, step in enumerate(f.extract_steps(ISO, size=SIZE, threads=1,
                                                                 rays_per_step=16)):
                            if k == rng.randrange(1, 4):
                                break
                    elif op == 4:
                        f.extract(ISO, size=SIZE, rays=64, threads=1,
                                  cache_mb=rng.choice((16, 17, 18)))
                    elif op == 5:
                        f.extract(ISO, size=SIZE, rays=64, threads=2, prefetch="always")
                    else:
                        f.camera(view=rng.choice(("+x", "-z")), size=SIZE)
                    count("ok")
                except RuntimeError as e:
                    if type(e) is not RuntimeError or str(e) != BUSY:
                        failures.append("%s: %r" % (type(e).__name__, e))
                    count("busy")
                except ValueError as e:
                    if not any(text in str(e) for text in DOCUMENTED):
                        failures.append("%s: %r" % (type(e).__name__, e))
                    count("documented")
                except BaseException as e:  # noqa: B902: anything else is a failure
                    failures.append("%s: %r" % (type(e).__name__, e))

        for r in range(rounds):
            f = isoprop.open(self.ibv)
            start = threading.Barrier(threads)

            def run(k, f=f, start=start, r=r):
                start.wait(60)
                hammer(f, 1000 * r + k, closer=(k == 0))

            workers = [threading.Thread(target=run, args=(k,)) for k in range(threads)]
            for w in workers:
                w.start()
            for w in workers:
                w.join(120)
                self.assertFalse(w.is_alive(), "a thread hangs")
            self.assertIsNone(f._store, "the closing thread did not close the file")
            self.assertFalse(f._runs)
            f.close()
        print("hammer: %d calls done, %d refused as busy, %d documented ValueErrors, close() "
              "refused %d times" % (tally["ok"], tally["busy"], tally["documented"],
                                    tally["close refused"]))
        self.assertEqual(failures, [])
        self.assertGreater(tally["ok"], rounds)


if __name__ == "__main__":
    support.main()
