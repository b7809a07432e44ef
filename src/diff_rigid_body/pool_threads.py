"""Calls run concurrently with a deadline, for :class:`~diff_rigid_body.pool.RigidBodyPool`.

Each instance of a pool has one :class:`Worker`: a long-lived thread that runs that instance's
calls one after the other, so its client (not thread-safe) is only ever used by that thread, and
the buffers the thread allocates are reused call after call (a thread per call would start each
time in a malloc arena whose pages have been returned to the kernel).
"""
import concurrent.futures
import queue
import threading
import time


class Worker(object):
    """A daemon thread running submitted functions in order."""

    def __init__(self, name):
        self._jobs = queue.Queue()
        threading.Thread(target=self._loop, name=name, daemon=True).start()

    def submit(self, function, *args):
        """A ``concurrent.futures.Future`` of ``(outcome, seconds)``: the function's return value or
        the exception it raised, and the wall time it ran (not counting its wait in the queue)."""
        future = concurrent.futures.Future()
        self._jobs.put((future, function, args))
        return future

    def _loop(self):
        while True:
            future, function, args = self._jobs.get()
            start = time.monotonic()
            try:
                outcome = function(*args)
            except Exception as error:  # handed to the caller, which decides what is a failure
                outcome = error
            future.set_result((outcome, time.monotonic() - start))


def wait_all(futures, timeout):
    """Per future of :meth:`Worker.submit`, in order: ``(outcome, seconds)``, or ``(None, None)``
    when it has not finished within ``timeout`` seconds (its worker goes on; the result is dropped)."""
    concurrent.futures.wait(futures, timeout=timeout)
    return [future.result() if future.done() else (None, None) for future in futures]
