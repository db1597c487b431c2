#!/usr/bin/env python3
"""kill -9 at 20 random moments while 8 clients submit 20 jobs each (issue 11, "Must show").

  crash_recovery_test.py BALLOON_SERVER TEST_DATA_DIR [--seed N]

One balloon-server on 127.0.0.1 (--workers 2, a token file with three tenants, one --db for every start).
8 client threads each submit 20 small jobs (simulate of a small icosphere, 2-second designs of a 162-vertex
sphere or ellipsoid, neo-Hookean fits of a Treloar CSV), each with its own request_id, retrying a call that
failed with UNAVAILABLE with the SAME request_id. Meanwhile the server is killed with SIGKILL 20 times at
seeded random moments, each time restarted at once on the same store and port; every 4th kill lands 5-50 ms
after 8 extra submissions went out at once, so some are stored but never answered and their retries must get
the stored job back (the count of those is printed, not asserted: it depends on timing). Afterwards, once nothing is
QUEUED or RUNNING: every accepted request maps to exactly one job, every job was submitted by a client, and
every job ended COMPLETED (with a stored result), FAILED or CANCELLED (with a reason). Then a job that is
running at each of three kills ends FAILED with "crashed the server 3 times" (default --max-attempts 3).
Exits 77 (ctest: skipped) when python3-grpcio is missing.
"""
import argparse
import math
import os
import random
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import threading
import time

SKIP = 77
SERVICE = "/balloon.v1.BalloonService/"
TENANTS = ["alice", "bob", "carol"]
TOKENS = {t: f"token-of-{t}-0123456789abcdef" for t in TENANTS}
CLIENTS, JOBS_PER_CLIENT, KILLS = 8, 20, 20
BURST_EVERY, BURST_SIZE = 4, 8  # every 4th kill lands 5-50 ms after 8 extra submissions were sent at once
EXPECTED_JOBS = CLIENTS * JOBS_PER_CLIENT + KILLS // BURST_EVERY * BURST_SIZE
SUBMIT_RETRY_S = 90.0   # a request still unanswered after this long is a failure of the test
DRAIN_TIMEOUT_S = 150.0  # after the last restart, every job must have ended within this
FINAL = ("JOB_STATE_COMPLETED", "JOB_STATE_FAILED", "JOB_STATE_CANCELLED")

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print(f"FAIL: {message}", flush=True)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def icosphere_obj(subdivisions, radius_mm, scale=(1.0, 1.0, 1.0)):
    """An icosphere (outward faces) as OBJ text; `scale` stretches it into an ellipsoid."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    vertices = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    vertices = [tuple(c / math.sqrt(1 + t * t) for c in v) for v in vertices]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoints, refined = {}, []

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                m = [(p + q) / 2 for p, q in zip(vertices[a], vertices[b])]
                n = math.sqrt(sum(c * c for c in m))
                vertices.append(tuple(c / n for c in m))
                midpoints[key] = len(vertices) - 1
            return midpoints[key]

        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            refined += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = refined
    lines = ["v %.9g %.9g %.9g" % tuple(radius_mm * c * s for c, s in zip(v, scale)) for v in vertices]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    return ("\n".join(lines) + "\n").encode()


class Server:
    """One balloon-server process; kill() and start() reuse the port and the store."""

    def __init__(self, binary, scratch):
        self.binary, self.scratch = binary, scratch
        self.port = free_port()
        self.db = os.path.join(scratch, "jobs.db")
        self.tokens = os.path.join(scratch, "tokens.txt")
        with open(self.tokens, "w") as f:
            f.writelines(f"{tenant} {token}\n" for tenant, token in TOKENS.items())
        self.process, self.starts = None, 0
        self.log = open(os.path.join(scratch, "server.log"), "a")

    @property
    def address(self):
        return f"127.0.0.1:{self.port}"

    def start(self, extra=()):
        self.starts += 1
        out_path = os.path.join(self.scratch, f"stdout.{self.starts}")
        with open(out_path, "w") as out:
            self.process = subprocess.Popen(
                [self.binary, "--listen", self.address, "--db", self.db, "--token-file", self.tokens,
                 "--workers", "2", *extra], stdout=out, stderr=self.log)
        deadline = time.time() + 30
        while time.time() < deadline:
            with open(out_path) as out:
                if "listening on" in out.read():
                    return
            if self.process.poll() is not None:
                break
            time.sleep(0.02)
        raise SystemExit(f"FAIL: the server did not start (start {self.starts}); see {self.log.name}")

    def kill(self):
        self.process.send_signal(signal.SIGKILL)
        self.process.wait(timeout=10)

    def stop(self):
        self.process.send_signal(signal.SIGTERM)
        return self.process.wait(timeout=30)


class Api:
    """The unary and streaming calls through grpc's generic channel API (grpc_tools is not in Debian)."""

    def __init__(self, grpc, pb, address):
        self.grpc, self.pb = grpc, pb
        # Reconnect quickly after a restart (the default back-off grows to 2 minutes).
        self.channel = grpc.insecure_channel(address, options=[
            ("grpc.initial_reconnect_backoff_ms", 100), ("grpc.min_reconnect_backoff_ms", 100),
            ("grpc.max_reconnect_backoff_ms", 300)])

        def unary(method, request_type, response_type):
            return self.channel.unary_unary(SERVICE + method, request_serializer=request_type.SerializeToString,
                                            response_deserializer=response_type.FromString)

        self.submit = unary("SubmitJob", pb.SubmitJobRequest, pb.SubmitJobResponse)
        self.get_job = unary("GetJob", pb.GetJobRequest, pb.Job)
        self.list_jobs = unary("ListJobs", pb.ListJobsRequest, pb.ListJobsResponse)

    def retrying(self, call, request, tenant, deadline_s=SUBMIT_RETRY_S):
        """`call` until it answers; UNAVAILABLE (server down or killed mid-call) is retried with the same request.
        Returns (reply, retries) or raises the last non-retryable error; self.last_try is when the answered
        call was sent."""
        give_up, retries = time.time() + deadline_s, 0
        while True:
            try:
                self.last_try = time.time()
                return call(request, timeout=10, metadata=[("authorization", f"Bearer {TOKENS[tenant]}")]), retries
            except self.grpc.RpcError as error:
                retryable = error.code() in (self.grpc.StatusCode.UNAVAILABLE, self.grpc.StatusCode.DEADLINE_EXCEEDED)
                if not retryable or time.time() > give_up:
                    raise
                retries += 1
                time.sleep(0.05)

    def all_jobs(self, tenant, state=None):
        jobs, token = [], ""
        while True:
            request = self.pb.ListJobsRequest(page_size=1000, page_token=token)
            if state is not None:
                request.state = state
            reply, _ = self.retrying(self.list_jobs, request, tenant)
            jobs += list(reply.jobs)
            token = reply.next_page_token
            if not token:
                return jobs


def job_request(pb, rng, data_dir, request_id):
    """A small job of a random kind: simulate, a 2 s design, or a fit."""
    kind = rng.choices(["simulate", "design", "fit"], weights=[4, 2, 4])[0]
    if kind == "simulate":
        spec = pb.JobSpec(simulate=pb.SimulateJob(
            rest_mesh=pb.MeshFile(data=icosphere_obj(rng.choice([1, 2]), 10.0), format=pb.MESH_FORMAT_OBJ),
            material=pb.MaterialRef(name="latex"), thickness_mm=0.5, volume_ratio=rng.uniform(1.5, 3.0)))
    elif kind == "design":
        scale = rng.choice([(1.0, 1.0, 1.0), (1.3, 1.0, 0.8)])
        spec = pb.JobSpec(design=pb.DesignJob(
            target_mesh=pb.MeshFile(data=icosphere_obj(2, 10.0, scale), format=pb.MESH_FORMAT_OBJ),
            material=pb.MaterialRef(name="latex"), thickness_mm=0.5, resolution=0, max_time_s=2.0))
    else:
        with open(os.path.join(data_dir, "materials", "treloar1944_ut.csv"), "rb") as f:
            csv = f.read()
        spec = pb.JobSpec(fit_material=pb.FitMaterialJob(
            data=[pb.MeasurementSet(csv=csv, test="uniaxial", label="treloar1944_ut.csv")], model="neo-hookean"))
    return kind, pb.SubmitJobRequest(spec=spec, request_id=request_id)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("server")
    parser.add_argument("data_dir")
    parser.add_argument("--seed", type=int, default=20261124)
    options = parser.parse_args()
    try:
        import grpc
        from balloon.v1 import balloon_pb2 as pb
    except ImportError as error:
        print(f"SKIP: {error} (python3-grpcio and the generated stubs on PYTHONPATH are needed)")
        return SKIP

    began = time.time()
    with tempfile.TemporaryDirectory() as scratch:
        server = Server(options.server, scratch)
        server.start()
        lock = threading.Lock()
        accepted = {}     # (tenant, request_id) -> job id, as the client was told
        attempted = set()  # (tenant, request_id) of every request sent, answered or not
        kinds = {}        # job id -> kind
        retries_total = [0]
        deduplicated = [0]  # retries answered with a job the store held before the retry was sent

        def submit_one(api, tenant, request_id, kind, request, who):
            with lock:
                attempted.add((tenant, request_id))
            try:
                reply, retries = api.retrying(api.submit, request, tenant)
            except grpc.RpcError as error:
                check(False, f"{who} request {request_id}: {error.code()} {error.details()}")
                return
            with lock:
                retries_total[0] += retries
                if retries and reply.job.created_ms < api.last_try * 1000:
                    deduplicated[0] += 1
                check((tenant, request_id) not in accepted, f"request {request_id} accepted twice")
                accepted[(tenant, request_id)] = reply.job.id
                kinds[reply.job.id] = kind

        def client(index):
            rng = random.Random(options.seed * 100 + index)
            tenant = TENANTS[index % len(TENANTS)]
            api = Api(grpc, pb, server.address)
            for n in range(JOBS_PER_CLIENT):
                request_id = f"c{index}-r{n}-{rng.getrandbits(32):08x}"
                kind, request = job_request(pb, rng, options.data_dir, request_id)
                submit_one(api, tenant, request_id, kind, request, f"client {index}")
                time.sleep(rng.uniform(0.2, 2.5))
            api.channel.close()

        def burst_submit(api, tenant, request_id):
            # Many submissions in flight when the kill lands: some are stored but never answered, and the retry
            # with the same request_id must return that job, not a second one.
            request = pb.SubmitJobRequest(request_id=request_id, spec=pb.JobSpec(simulate=pb.SimulateJob(
                rest_mesh=pb.MeshFile(data=icosphere_obj(1, 10.0), format=pb.MESH_FORMAT_OBJ),
                material=pb.MaterialRef(name="latex"), thickness_mm=0.5, volume_ratio=2.0)))
            submit_one(api, tenant, request_id, "simulate", request, "burst")

        threads = [threading.Thread(target=client, args=(i,)) for i in range(CLIENTS)]
        for thread in threads:
            thread.start()
        burst_api = Api(grpc, pb, server.address)
        killer_rng = random.Random(options.seed)
        for k in range(KILLS):
            time.sleep(killer_rng.uniform(0.5, 3.0))
            if k % BURST_EVERY == BURST_EVERY - 1:
                burst = [threading.Thread(target=burst_submit, args=(burst_api, TENANTS[i % len(TENANTS)],
                                                                     f"burst{k}-{i}")) for i in range(BURST_SIZE)]
                for thread in burst:
                    thread.start()
                threads += burst
                time.sleep(killer_rng.uniform(0.005, 0.05))
            server.kill()
            server.start()
        killed_at = time.time()
        for thread in threads:
            thread.join()
        burst_api.channel.close()
        print(f"{KILLS} kills in {killed_at - began:.1f} s; {len(accepted)} of {len(attempted)} requests accepted "
              f"({retries_total[0]} retried calls, {deduplicated[0]} answered by request_id with the job stored "
              f"before the kill); clients done at {time.time() - began:.1f} s", flush=True)

        # Every job must end: nothing QUEUED or RUNNING, bounded.
        api = Api(grpc, pb, server.address)
        deadline = time.time() + DRAIN_TIMEOUT_S
        while True:
            listed = {t: api.all_jobs(t) for t in TENANTS}
            unfinished = [j.id for jobs in listed.values() for j in jobs if pb.JobState.Name(j.state) not in FINAL]
            if not unfinished or time.time() > deadline:
                break
            time.sleep(0.5)
        check(not unfinished, f"{len(unfinished)} job(s) still unfinished {DRAIN_TIMEOUT_S} s after the last "
                              f"restart: {unfinished[:5]}")
        print(f"all jobs ended at {time.time() - began:.1f} s", flush=True)

        # Exactly once: accepted requests <-> listed jobs, one to one, each owned by its submitter.
        owner = {j.id: t for t, jobs in listed.items() for j in jobs}
        all_listed = [j for jobs in listed.values() for j in jobs]
        check(len(owner) == len(all_listed), "a job id is listed twice")
        check(len(accepted) == EXPECTED_JOBS, f"{EXPECTED_JOBS - len(accepted)} request(s) never accepted")
        job_ids = list(accepted.values())
        check(len(set(job_ids)) == len(job_ids), "two requests were given the same job")
        for (tenant, request_id), job_id in accepted.items():
            check(owner.get(job_id) == tenant, f"accepted job {job_id} ({request_id}) is not listed for {tenant}: "
                                               f"lost")
        extra = set(owner) - set(job_ids)
        check(not extra, f"{len(extra)} job(s) no client was told about (duplicates): {sorted(extra)[:5]}")
        counts = {}
        for job in all_listed:
            state = pb.JobState.Name(job.state)
            counts[(kinds.get(job.id, "?"), state)] = counts.get((kinds.get(job.id, "?"), state), 0) + 1
            if state in ("JOB_STATE_FAILED", "JOB_STATE_CANCELLED"):
                check(job.error.strip() != "", f"job {job.id} is {state} without a reason")
        crashed = [j for j in all_listed if "crashed the server" in j.error]
        rerun = sum(1 for j in all_listed if j.attempts > 1)
        other_failures = [(j.id, kinds.get(j.id), j.error) for j in all_listed
                          if pb.JobState.Name(j.state) == "JOB_STATE_FAILED" and "crashed the server" not in j.error]
        print(f"end states: {sorted(counts.items())}; {rerun} job(s) re-run after a kill, {len(crashed)} failed "
              f"by --max-attempts", flush=True)
        # The kills must have hit work in flight, else this run proved nothing.
        check(rerun > 0, "no kill landed while a job was running")
        check(retries_total[0] > 0, "no kill landed during a submission")
        for failed in other_failures[:10]:
            print(f"  failed: {failed}", flush=True)

        # A job that crashes the server every time it runs: kill whenever it is RUNNING, three times. It
        # must run well beyond the 50 ms poll: a sphere's design is done in about that, an ellipsoid's is not.
        heavy = pb.SubmitJobRequest(request_id="crasher", spec=pb.JobSpec(design=pb.DesignJob(
            target_mesh=pb.MeshFile(data=icosphere_obj(3, 10.0, scale=(1.6, 1.0, 0.8)), format=pb.MESH_FORMAT_OBJ),
            material=pb.MaterialRef(name="latex"), thickness_mm=0.5, resolution=0, max_time_s=60.0)))
        crasher = api.retrying(api.submit, heavy, "alice")[0].job.id
        for attempt in range(1, 4):
            deadline = time.time() + 30
            while True:
                job = api.retrying(api.get_job, pb.GetJobRequest(job_id=crasher), "alice")[0]
                if job.state == pb.JOB_STATE_RUNNING or time.time() > deadline:
                    break
                time.sleep(0.05)
            check(job.state == pb.JOB_STATE_RUNNING and job.attempts == attempt,
                  f"crasher start {attempt}: {pb.JobState.Name(job.state)}, attempts {job.attempts}")
            server.kill()
            server.start()
        job = api.retrying(api.get_job, pb.GetJobRequest(job_id=crasher), "alice")[0]
        check(job.state == pb.JOB_STATE_FAILED, f"crasher is {pb.JobState.Name(job.state)}, not FAILED")
        check("crashed the server 3 times" in job.error, f"crasher's reason: {job.error!r}")
        check(job.attempts == 3, f"crasher attempts {job.attempts}")
        print(f"crasher {crasher}: {pb.JobState.Name(job.state)} after {job.attempts} starts: {job.error}", flush=True)
        api.channel.close()
        check(server.stop() == 0, "the server did not exit cleanly on SIGTERM")

        # The store agrees: one row per request, a result for every COMPLETED job, a reason for every other.
        db = sqlite3.connect(server.db)
        dup = db.execute("SELECT owner, request_id, COUNT(*) FROM jobs GROUP BY owner, request_id "
                         "HAVING COUNT(*) > 1").fetchall()
        check(not dup, f"duplicated requests in the store: {dup[:5]}")
        rows = db.execute("SELECT owner, request_id, job_id FROM jobs").fetchall()
        check(len(rows) == len(accepted) + 1, f"the store holds {len(rows)} jobs, {len(accepted) + 1} accepted")
        for tenant, request_id, job_id in rows:
            check((tenant, request_id) in attempted or request_id == "crasher",
                  f"stored job {job_id} ({tenant}, {request_id!r}) was never submitted")
        no_result = db.execute("SELECT job_id FROM jobs WHERE state = 'completed' AND id NOT IN "
                               "(SELECT job_row FROM results)").fetchall()
        check(not no_result, f"COMPLETED without a stored result: {no_result[:5]}")
        unreasoned = db.execute("SELECT job_id, state FROM jobs WHERE state <> 'completed' AND error = ''").fetchall()
        check(not unreasoned, f"ended without a result or a reason: {unreasoned[:5]}")
        db.close()
        if failures:
            print(f"server log tail:\n{''.join(open(server.log.name).readlines()[-30:])}")

    print(f"{'FAILED' if failures else 'passed'}: {len(failures)} failure(s) in {time.time() - began:.1f} s")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
