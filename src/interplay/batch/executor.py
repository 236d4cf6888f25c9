"""Executors: where the runs of a sweep or the evaluations of a search go.

One small interface, shared by ``interplay sweep``, ``interplay tune`` and anything else that
runs many independent simulations: ``with make_executor(workers, ray) as ex: for i, value in
ex.map_unordered(fn, items): ...`` yields each item's result as soon as it is done (the
caller puts them back in order). ``fn`` must be a module-level function and ``items``
picklable: they cross a process boundary, or a network to a Ray node.

- ``LocalPool`` (default): one worker process per core, started with ``spawn`` (no forked
  copies of Numba's threads or the GL context), each single-threaded: a run already keeps
  one core busy, and Numba's or OpenBLAS's own threads would only fight over the cores.
- ``RayCluster`` (``--ray [ADDRESS]``): the same tasks as Ray tasks (one CPU each) on an
  existing cluster (``ray start --head`` on this or another machine), or on a local instance
  when no cluster is found. Nodes may not share this machine's disk, so ``shared_files`` is
  False: a task returns its outputs as data and the caller writes them (``pack``/``unpack``).
  Every node must run the same Interplay: the first task compares the source digest.

A task that raises comes back as a ``Failure`` (the error's text); so does a task whose
worker died (killed, out of memory, a crash in native code): the pool is rebuilt and the
remaining tasks go on. Numba compiles into its on-disk cache once per source file: the caller
warms it (``warm``) before the workers start, so that they load rather than compile.
"""
from __future__ import annotations

import hashlib
import io
import os
import socket
import tarfile
import tempfile
import time
import traceback
from collections import deque
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from ..errors import InterplayError, ParameterError

#: what every worker runs with: one thread for Numba, BLAS, OpenMP and Mesa's llvmpipe
WORKER_ENV = {"NUMBA_NUM_THREADS": "1", "NUMBA_THREADING_LAYER": "workqueue",
              "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "LP_NUM_THREADS": "1"}
RAY_RETRIES = 1  # Ray reruns a task whose worker died once, then reports it


@dataclass(frozen=True)
class Failure:
    """A task that did not return: kind ("error": it raised; "worker": its worker died),
    message (one line), detail (the traceback, or what is known), exit status (2 for an
    InterplayError, the CLI's own; 1 otherwise)."""
    kind: str
    message: str
    detail: str = ""
    exit: int = 1

    @classmethod
    def of(cls, e: BaseException) -> "Failure":
        msg = str(e) if isinstance(e, InterplayError) else f"{type(e).__name__}: {e}"
        return cls("error", msg.splitlines()[0] if msg else type(e).__name__,
                   "".join(traceback.format_exception(e)), 2 if isinstance(e, InterplayError)
                   else 1)


def guarded(fn, item):
    """fn(item), or the Failure it raised (runs in the worker)."""
    try:
        return fn(item)
    except Exception as e:  # every failure is reported with its variant; the batch goes on
        return Failure.of(e)


def code_digest() -> str:
    """A digest of Interplay's Python sources (which code a worker runs)."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for p in sorted(root.rglob("*.py")):
        h.update(p.relative_to(root).as_posix().encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:16]


def worker_info() -> dict:
    """Who ran a task: host, process id, Numba's thread count, the code digest."""
    import numba
    return {"host": socket.gethostname(), "pid": os.getpid(),
            "numba_threads": int(numba.config.NUMBA_NUM_THREADS), "code": code_digest()}


@contextmanager
def worker_environment():
    """WORKER_ENV in os.environ while workers are started (a spawned process inherits it
    before it imports Numba); the caller's values come back afterwards."""
    saved = {k: os.environ.get(k) for k in WORKER_ENV}
    os.environ.update(WORKER_ENV)
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


class LocalPool:
    """``workers`` single-threaded processes on this machine (default: one per core)."""
    kind = "local"
    shared_files = True

    def __init__(self, workers: int | None = None):
        self.workers = check_workers(workers)
        self.address = None
        self._pool = None

    def __enter__(self):
        self._env = worker_environment()
        self._env.__enter__()
        self._start()
        return self

    def __exit__(self, *exc):
        self._stop(kill=exc[0] is not None)
        self._env.__exit__(None, None, None)

    def _start(self):
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor
        self._pool = ProcessPoolExecutor(self.workers, mp_context=mp.get_context("spawn"))

    def _stop(self, kill=False):
        if self._pool is None:
            return
        if kill:  # interrupted: do not wait for the runs in flight
            for p in list(getattr(self._pool, "_processes", {}).values()):
                p.kill()
        self._pool.shutdown(wait=True, cancel_futures=True)
        self._pool = None

    def map_unordered(self, fn, items):
        """Yield (index, fn(item) or Failure) as tasks finish. At most ``workers`` are in
        flight; when a worker dies, the pool is rebuilt and the tasks that were in flight
        are rerun one at a time, so the one that kills its worker is found and failed alone
        and the others finish."""
        from concurrent.futures import FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool
        queue = deque((i, item, False) for i, item in enumerate(items))  # False: not suspect
        running = {}
        while queue or running:
            while queue and len(running) < self.workers:
                if any(s for _, _, s in running.values()) or (queue[0][2] and running):
                    break  # a suspect runs alone
                i, item, suspect = queue.popleft()
                running[self._pool.submit(guarded, fn, item)] = (i, item, suspect)
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            broken = False
            for f in done:
                i, item, suspect = running.pop(f)
                try:
                    yield i, f.result()
                except BrokenProcessPool:
                    broken = True
                    if suspect:
                        yield i, Failure("worker", "its worker process died (killed, out of "
                                         "memory or a crash in native code)")
                    else:
                        queue.appendleft((i, item, True))
            if broken:
                for i, item, _ in running.values():
                    queue.appendleft((i, item, True))
                running.clear()
                self._stop()
                self._start()


class RayCluster:
    """Tasks on a Ray cluster: ``address`` as for ``ray.init`` (None: $RAY_ADDRESS, else the
    cluster ``ray start`` began on this machine, else a new local instance)."""
    kind = "ray"
    shared_files = False

    def __init__(self, address: str | None = None):
        self.address = address
        self.workers = 0

    def __enter__(self):
        # `ray start` turns token authentication on and keeps the token in ~/.ray; a driver
        # given an address sends it only in token mode, which Ray reads when it is imported
        self._auth = os.environ.get("RAY_AUTH_MODE")
        if self._auth is None and (os.environ.get("RAY_AUTH_TOKEN") or (
                Path.home() / ".ray" / "auth_token").exists()):
            os.environ["RAY_AUTH_MODE"] = "token"
        try:
            import ray
        except ImportError:
            self._restore_auth()
            raise InterplayError("--ray needs Ray: pip install 'ray>=2.9' (or `make "
                                 "test-all`), or leave out --ray to use the local cores") from None
        self._ray = ray
        env = {"env_vars": dict(WORKER_ENV)}
        try:
            ray.init(address=self.address, runtime_env=env, include_dashboard=False,
                     log_to_driver=False, configure_logging=False)
        except (ConnectionError, ValueError, RuntimeError) as e:
            self._restore_auth()
            raise InterplayError(f"--ray {self.address or ''}: cannot connect to a Ray cluster "
                                 f"({str(e).splitlines()[0]}); start one with `ray start "
                                 "--head` or give its ADDRESS (host:port), and its token "
                                 "(RAY_AUTH_TOKEN) if it has one") from None
        self.workers = max(int(ray.cluster_resources().get("CPU", 1)), 1)
        self._remote = ray.remote(num_cpus=1, max_retries=RAY_RETRIES)(guarded)
        info = ray.get(self._remote.remote(_probe, None))
        if isinstance(info, Failure) or info["code"] != code_digest():
            got = info.message if isinstance(info, Failure) else f"code {info['code']}"
            self.__exit__(None, None, None)
            raise InterplayError(f"the Ray cluster runs a different Interplay ({got}; this "
                                 f"one is {code_digest()}): install the same version on every "
                                 "node, or leave out --ray")
        return self

    def __exit__(self, *exc):
        self._ray.shutdown()
        self._restore_auth()

    def _restore_auth(self):
        if self._auth is None:
            os.environ.pop("RAY_AUTH_MODE", None)

    def map_unordered(self, fn, items):
        ray = self._ray
        refs = {self._remote.remote(fn, item): i for i, item in enumerate(items)}
        try:
            while refs:
                ready, _ = ray.wait(list(refs), num_returns=1)
                for r in ready:
                    i = refs.pop(r)
                    try:
                        yield i, ray.get(r)
                    except ray.exceptions.RayError as e:
                        yield i, Failure("worker", f"its Ray worker failed: "
                                         f"{str(e).splitlines()[0]}", str(e))
        finally:
            for r in refs:
                ray.cancel(r, force=True)


def _probe(_):
    return worker_info()


@contextmanager
def local_ray_head(cpus: int = 2, env: dict | None = None, timeout_s: float = 180.0):
    """A one-node Ray cluster on this machine (``ray start --head --block``) for tests and
    benchmarks; yields its address. It runs in its own session and is stopped by signalling
    that process group (``ray stop`` would stop every Ray cluster on the machine). env: extra
    environment for it and its workers (e.g. PYTHONPATH)."""
    import shutil
    import signal
    import subprocess
    import sys
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    tmp = Path(tempfile.mkdtemp(prefix="ipray"))  # short: Ray's socket paths fit in 107 bytes
    log = tmp / "head.log"
    ray_cli = shutil.which("ray") or str(Path(sys.executable).parent / "ray")
    with open(log, "w") as fh:
        proc = subprocess.Popen([ray_cli, "start", "--head", f"--port={port}",
                                 f"--num-cpus={cpus}", "--include-dashboard=false",
                                 "--disable-usage-stats", f"--temp-dir={tmp}", "--block"],
                                env={**os.environ, **(env or {})}, stdout=fh,
                                stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + timeout_s
        while "Ray runtime started" not in log.read_text():
            if proc.poll() is not None or time.monotonic() > deadline:
                raise InterplayError(f"ray start --head did not start: "
                                     f"{log.read_text()[-500:]}")
            time.sleep(0.5)
        yield f"127.0.0.1:{port}"
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(5)
        except subprocess.TimeoutExpired:
            pass
        os.killpg(proc.pid, signal.SIGKILL)  # what SIGTERM left (the raylet is slow to go)
        proc.wait()
        shutil.rmtree(tmp, ignore_errors=True)


def check_workers(workers) -> int:
    n = (os.cpu_count() or 1) if workers is None else workers
    if not isinstance(n, int) or n < 1:
        raise ParameterError(f"--workers {workers}: need a whole number of processes >= 1 "
                             f"(this machine has {os.cpu_count()} cores)")
    return n


def make_executor(workers: int | None = None, ray: str | bool | None = None):
    """The executor the command line asked for: ``--ray [ADDRESS]`` (ray True for no
    address) or else a local pool of ``workers`` processes (default one per core)."""
    if ray:
        if workers is not None:
            raise ParameterError("--workers applies to the local pool; Ray runs one task per "
                                 "CPU of the cluster: leave out one of --workers and --ray")
        return RayCluster(None if ray is True else str(ray))
    return LocalPool(workers)


def pack(folder) -> bytes:
    """A folder's files as an uncompressed tar (its videos and npz are compressed already)."""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w") as tar:
        tar.add(str(folder), arcname=".")
    return buf.getvalue()


def unpack(data: bytes, folder) -> Path:
    """Write a ``pack``ed folder's files into ``folder`` (no path may leave it)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r") as tar:
        tar.extractall(folder, filter="data")
    return folder
