#!/usr/bin/env python3
"""Three balloon-server shards behind the Debian HAProxy on 127.0.0.1 (issue 13), driven with the CLI.

  balancer_test.py --server BALLOON_SERVER --cli BALLOON_CLI --config deploy/loadbalancer/haproxy.cfg [--measure]

Checks: 6 tenants submit 30 jobs through the balancer and each tenant's jobs land on one shard and list only
there; kill -9 of a shard mid-job (its tenants are retried elsewhere or refused, the others see nothing; after
the restart its job completes); SIGTERM of a shard (NOT_SERVING on grpc.health.v1, the balancer takes it out,
its job completes after the restart); the HTTP gateway through the balancer (same shard as gRPC, SSE events,
a file download); finally the union of the three stores equals what was submitted, each job once.
--measure also prints SubmitJob latency and jobs per second through the balancer against direct.
Exits 77 (ctest: skipped) when haproxy or python3-grpcio is missing.
"""
import argparse
import base64
import json
import os
import re
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

SKIP = 77
TENANTS = [f"tenant{i}" for i in range(6)]
TOKENS = {t: f"token-of-{t}-0123456789abcdef" for t in TENANTS}
SHARDS = ["s0", "s1", "s2"]
DRAIN_TIMEOUT_S = 10


def fail(message):
    print(f"FAIL: {message}", flush=True)
    raise SystemExit(1)


def check(condition, message):
    if not condition:
        fail(message)


_handed_out = set()


def free_port():
    """A loopback port free now, never one handed out before: only the balancer needs a port known before it
    binds (its config names them); the shards bind port 0 and report theirs."""
    while True:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        if port not in _handed_out:
            _handed_out.add(port)
            return port


class Shard:
    """One balloon-server: gRPC and HTTP on loopback ports it picks at its first start (port 0, read from its
    first lines) and keeps on a restart, since the balancer's config names them."""

    def __init__(self, name, server, scratch, tokens, public_origin):
        self.name, self.server, self.scratch, self.tokens = name, server, scratch, tokens
        self.public_origin = public_origin  # the balancer's address: the Host the page's requests carry
        self.grpc_port, self.http_port = 0, 0
        self.db = os.path.join(scratch, f"{name}.db")
        self.process = None

    @property
    def grpc(self):
        return f"127.0.0.1:{self.grpc_port}"

    def start(self):
        log = open(os.path.join(self.scratch, f"{self.name}.log"), "a")
        self.process = subprocess.Popen(
            [self.server, "--listen", self.grpc, "--http", f"127.0.0.1:{self.http_port}", "--db", self.db,
             "--shard-name", self.name, "--token-file", self.tokens, "--workers", "1",
             "--drain-timeout", str(DRAIN_TIMEOUT_S), "--web-root", self.scratch,
             "--http-allowed-origin", self.public_origin],
            stdout=subprocess.PIPE, stderr=log, text=True)
        # Both lines come in one write once the server listens; a server that fails closes its stdout.
        output = ""
        while "http on" not in output:
            line = self.process.stdout.readline()
            if not line:
                break
            output += line
        check("http on" in output, f"{self.name} did not start: {output!r}")
        # "... listening on 127.0.0.1:PORT (...)" and "... http on 127.0.0.1:PORT (...)"
        self.grpc_port = int(output.split("listening on ", 1)[1].split(" ", 1)[0].rsplit(":", 1)[1])
        self.http_port = int(output.split("http on ", 1)[1].split(" ", 1)[0].rsplit(":", 1)[1])
        _handed_out.update((self.grpc_port, self.http_port))

    def stop(self, sig):
        self.process.send_signal(sig)
        code = self.process.wait(timeout=DRAIN_TIMEOUT_S + 5)
        self.process.stdout.close()
        return code


class Balancer:
    def __init__(self, config, scratch, shards, http_port):
        self.grpc_port, self.http_port, self.stats_port = free_port(), http_port, free_port()
        env = dict(os.environ, BALLOON_LB_GRPC_BIND=f"127.0.0.1:{self.grpc_port}",
                   BALLOON_LB_HTTP_BIND=f"127.0.0.1:{self.http_port}",
                   BALLOON_LB_STATS_BIND=f"127.0.0.1:{self.stats_port}")
        for i, shard in enumerate(shards):
            env[f"BALLOON_SHARD{i}_GRPC"] = shard.grpc
            env[f"BALLOON_SHARD{i}_HTTP"] = f"127.0.0.1:{shard.http_port}"
        self.log_path = os.path.join(scratch, "haproxy.log")
        self.process = subprocess.Popen(["haproxy", "-f", config, "-db"], env=env,
                                        stdout=open(self.log_path, "w"), stderr=subprocess.STDOUT)

    @property
    def grpc(self):
        return f"127.0.0.1:{self.grpc_port}"

    def states(self):
        """{(backend, server): 'UP'|'DOWN'|...} from the stats CSV."""
        with urllib.request.urlopen(f"http://127.0.0.1:{self.stats_port}/stats;csv", timeout=5) as reply:
            rows = reply.read().decode().splitlines()
        header = rows[0].lstrip("# ").split(",")
        states = {}
        for row in rows[1:]:
            fields = dict(zip(header, row.split(",")))
            if fields.get("svname", "").startswith("shard"):
                states[(fields["pxname"], fields["svname"])] = fields["status"].split(" ")[0]
        return states

    def wait_for(self, server, state, timeout_s=15):
        deadline = time.time() + timeout_s
        while time.time() < deadline:
            try:
                current = self.states()
                if all(current.get((backend, server)) == state for backend in ("balloon_grpc", "balloon_http")):
                    return time.time()
            except OSError:
                pass
            time.sleep(0.2)
        fail(f"the balancer did not report {server} {state} within {timeout_s} s: {self.states()}")

    def stop(self):
        self.process.send_signal(signal.SIGTERM)
        self.process.wait(timeout=10)


class Cli:
    def __init__(self, path):
        self.path = path

    def run(self, args, tenant, server, timeout=120):
        return subprocess.run([self.path, *args, "--server", server, "--token", TOKENS[tenant]],
                              capture_output=True, text=True, timeout=timeout)

    def json(self, args, tenant, server):
        result = self.run([*args, "--json"], tenant, server)
        check(result.returncode == 0, f"balloon {' '.join(args)} ({tenant}) exited {result.returncode}: {result.stderr}")
        return json.loads(result.stdout)

    def listed(self, tenant, server):
        return {job["id"]: job for job in self.json(["jobs", "list", "--limit", "1000"], tenant, server)["jobs"]}


def shard_of(job_id):
    return job_id.split("-j-")[0]


def wait_until(predicate, timeout_s, what):
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        if predicate():
            return
        time.sleep(0.2)
    fail(f"timed out after {timeout_s} s waiting for {what}")


def health_watch(address, seen, done):
    """Follows grpc.health.v1.Health/Watch (service "") on `address`; appends each status (1 SERVING, 2 NOT_SERVING)."""
    import grpc
    with grpc.insecure_channel(address) as channel:
        watch = channel.unary_stream("/grpc.health.v1.Health/Watch", request_serializer=lambda _: b"",
                                     response_deserializer=lambda data: data[1] if len(data) >= 2 else 0)
        try:
            for status in watch(None, timeout=60):
                seen.append(status)
        except grpc.RpcError:
            pass
    done.set()


def http_request(url, token, body=None):
    request = urllib.request.Request(url, data=body, method="POST" if body is not None else "GET",
                                     headers={"Authorization": f"Bearer {token}", "Content-Type": "application/json"})
    return urllib.request.urlopen(request, timeout=60)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--server", required=True)
    parser.add_argument("--cli", required=True)
    parser.add_argument("--config", required=True)
    parser.add_argument("--measure", action="store_true")
    options = parser.parse_args()
    if shutil.which("haproxy") is None:
        print("SKIP: haproxy is not installed (deploy/install-deps.sh installs Debian's haproxy)")
        return SKIP
    try:
        import grpc  # noqa: F401
    except ImportError:
        print("SKIP: python3-grpcio is not installed (deploy/install-deps.sh installs it)")
        return SKIP

    started = time.time()
    scratch = tempfile.mkdtemp(prefix="balloon-balancer-")
    tokens = os.path.join(scratch, "tokens")
    with open(tokens, "w") as f:
        f.writelines(f"{tenant} {TOKENS[tenant]}\n" for tenant in TENANTS)
    cli = Cli(options.cli)
    small, large = (os.path.join(scratch, f"{size}.obj") for size in ("small", "large"))
    for path, subdivisions in ((small, 2), (large, 5)):
        made = subprocess.run([options.cli, "mesh", "sphere", "--radius", "10", "--subdivisions", str(subdivisions),
                               "--out", path], capture_output=True, text=True)
        check(made.returncode == 0, made.stderr)

    balancer_http_port = free_port()
    shards = [Shard(name, options.server, scratch, tokens, f"http://127.0.0.1:{balancer_http_port}")
              for name in SHARDS]
    for shard in shards:
        shard.start()
    balancer = Balancer(options.config, scratch, shards, balancer_http_port)
    try:
        for i in range(len(shards)):
            balancer.wait_for(f"shard{i}", "UP")
        submitted = run_scenario(cli, shards, balancer, small, large, scratch)
        if options.measure:
            submitted.update(measure(cli, shards, balancer, small))
    finally:
        for shard in shards:
            if shard.process and shard.process.poll() is None:
                shard.stop(signal.SIGTERM)
        balancer.stop()

    # Nothing lost, nothing duplicated: the union of the three stores is exactly what was submitted.
    stored = {}
    for shard in shards:
        with sqlite3.connect(shard.db) as db:
            for job_id, owner, state in db.execute("SELECT job_id, owner, state FROM jobs ORDER BY id"):
                check(job_id not in stored, f"job {job_id} is in two stores")
                check(shard_of(job_id) == shard.name, f"{shard.name}'s store holds {job_id}")
                stored[job_id] = (owner, state)
    check(set(stored) == set(submitted), f"stores {sorted(set(stored) ^ set(submitted))} differ from submissions")
    for job_id, (owner, state) in stored.items():
        check(owner == submitted[job_id], f"{job_id} belongs to {owner}, submitted by {submitted[job_id]}")
        check(state == "completed", f"{job_id} ended {state}")
    shutil.rmtree(scratch, ignore_errors=True)
    print(f"PASS: {len(stored)} jobs on {len(shards)} shards, each stored once and completed "
          f"({time.time() - started:.1f} s)")
    return 0


def run_scenario(cli, shards, balancer, small, large, scratch):
    """Returns {job_id: tenant} for every job submitted."""
    lb = balancer.grpc
    by_name = {shard.name: shard for shard in shards}
    submitted = {}

    # 1. 6 tenants x 5 jobs through the balancer: simulations, and one small design for two of them.
    errors = []

    def tenant_jobs(index, tenant):
        try:
            for k in range(4 if index < 2 else 5):
                job = cli.json(["submit", small, "--material", "latex", "--volume-ratio", f"{1.5 + 0.1 * k:.1f}"],
                               tenant, lb)
                submitted[job["id"]] = tenant
            if index < 2:
                design = cli.run(["design", small, "--material", "latex", "--resolution", "0", "--max-time", "2",
                                  "--out-dir", os.path.join(scratch, f"design-{tenant}")], tenant, lb)
                check(design.returncode in (0, 3), f"design of {tenant} exited {design.returncode}: {design.stderr}")
                ids = set(re.findall(r"\b(s\d-j-[0-9a-f]{16})\b", design.stderr))
                check(len(ids) == 1, f"design of {tenant}: job ids {ids} in {design.stderr[-400:]}")
                submitted[ids.pop()] = tenant
        except SystemExit as error:
            errors.append(error)

    threads = [threading.Thread(target=tenant_jobs, args=(i, t)) for i, t in enumerate(TENANTS)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    check(not errors, "a tenant's submissions failed")
    check(len(submitted) == 30, f"{len(submitted)} jobs submitted, 30 expected")

    home = {}
    for tenant in TENANTS:
        mine = {job_id for job_id, owner in submitted.items() if owner == tenant}
        wait_until(lambda: all(j["state"] == "JOB_STATE_COMPLETED" for j in cli.listed(tenant, lb).values()), 90,
                   f"{tenant}'s jobs to complete")
        check(set(cli.listed(tenant, lb)) == mine, f"{tenant} lists other jobs through the balancer")
        places = {shard_of(job_id) for job_id in mine}
        check(len(places) == 1, f"{tenant}'s jobs landed on {places}")
        home[tenant] = places.pop()
        for shard in shards:  # ... and list only there
            direct = set(cli.listed(tenant, shard.grpc))
            check(direct == (mine if shard.name == home[tenant] else set()), f"{tenant} on {shard.name}: {direct}")
    print(f"phase 1: 30 jobs completed; tenants per shard: {home}", flush=True)
    check(len(set(home.values())) >= 2, "the tenants' tokens hash to one shard only; pick other tokens")

    # 2. kill -9 a shard mid-job.
    victim_tenant = TENANTS[0]
    victim = by_name[home[victim_tenant]]
    long_job = cli.json(["submit", large, "--material", "latex", "--volume-ratio", "125"], victim_tenant, lb)["id"]
    submitted[long_job] = victim_tenant
    wait_until(lambda: cli.json(["jobs", "show", long_job], victim_tenant, lb)["state"] == "JOB_STATE_RUNNING", 30,
               "the long job to run")
    check(victim.stop(signal.SIGKILL) == -signal.SIGKILL, "kill -9 did not kill")
    for tenant in TENANTS:  # everybody submits once while the victim is down
        result = cli.run(["submit", small, "--material", "latex", "--volume-ratio", "2", "--json"], tenant, lb)
        if home[tenant] != victim.name:
            check(result.returncode == 0, f"{tenant} (on {home[tenant]}) noticed the outage: {result.stderr}")
        if result.returncode == 0:
            job_id = json.loads(result.stdout)["id"]
            submitted[job_id] = tenant
            if home[tenant] != victim.name:
                check(shard_of(job_id) == home[tenant], f"{tenant}'s job moved to {job_id}")
            else:
                print(f"phase 2: {tenant}'s submission was retried on {shard_of(job_id)}", flush=True)
        else:  # refused: UNAVAILABLE (exit 5)
            check(result.returncode == 5, f"{tenant}: exit {result.returncode}: {result.stderr}")
    shown = cli.run(["jobs", "show", long_job], victim_tenant, lb)
    check(shown.returncode != 0 and ("belongs to shard " + victim.name in shown.stderr or shown.returncode == 5),
          f"the dead shard's job: exit {shown.returncode}: {shown.stderr}")
    print(f"phase 2: {victim.name} killed; its job reads: {shown.stderr.strip()}", flush=True)
    victim.start()
    balancer.wait_for(f"shard{SHARDS.index(victim.name)}", "UP")
    watched = cli.run(["jobs", "watch", long_job], victim_tenant, lb)
    check(watched.returncode == 0, f"the recovered job: exit {watched.returncode}: {watched.stderr[-400:]}")
    attempts = cli.json(["jobs", "show", long_job], victim_tenant, lb)["attempts"]
    check(attempts == 2, f"the killed job ran {attempts} time(s), 2 expected (killed, then again)")

    # 3. SIGTERM a shard mid-job: NOT_SERVING, taken out of the balancer, the job completes after the restart.
    drained_tenant = next(t for t in TENANTS if home[t] != victim.name)
    drained = by_name[home[drained_tenant]]
    index = SHARDS.index(drained.name)
    seen, watch_done = [], threading.Event()
    threading.Thread(target=health_watch, args=(drained.grpc, seen, watch_done), daemon=True).start()
    wait_until(lambda: seen == [1], 10, "the health watch to report SERVING")
    # A design bounded by its own 15 s budget: still running when SIGTERM arrives however fast the solver
    # gets (a simulation of any size can finish first), and it ends in bounded time after the restart.
    spot = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "meshes", "spot.obj")
    with open(spot, "rb") as f:
        design = {"spec": {"design": {"target_mesh": {"data": base64.b64encode(f.read()).decode(),
                                                      "format": "MESH_FORMAT_OBJ"},
                                      "material": {"name": "silicone"}, "size_mm": 100, "resolution": 1500,
                                      "max_time_s": 15}}}
    with http_request(f"http://127.0.0.1:{balancer.http_port}/api/v1/jobs", TOKENS[drained_tenant],
                      json.dumps(design).encode()) as reply:
        drained_job = json.loads(reply.read())["job"]["id"]
    submitted[drained_job] = drained_tenant
    # Past a few design iterations, and a second more: the design has stored a checkpoint to resume from.
    def design_iteration():
        progress = cli.json(["jobs", "show", drained_job], drained_tenant, lb).get("last_progress", {})
        return progress.get("iteration", 0) if progress.get("phase") == "design" else 0
    wait_until(lambda: design_iteration() >= 2, 60, "the design to drain to iterate")
    time.sleep(1.2)
    term_at = time.time()
    check(drained.stop(signal.SIGTERM) == 0, "the drained server did not exit cleanly")
    exit_s = time.time() - term_at
    check(exit_s < DRAIN_TIMEOUT_S, f"draining took {exit_s:.1f} s")
    watch_done.wait(10)
    check(2 in seen, f"health statuses seen during the drain: {seen} (2 = NOT_SERVING expected)")
    out_s = balancer.wait_for(f"shard{index}", "DOWN") - term_at
    print(f"phase 3: {drained.name} drained in {exit_s:.2f} s; health {seen}; balancer took it out after "
          f"{out_s:.1f} s", flush=True)
    drained.start()
    balancer.wait_for(f"shard{index}", "UP")
    watched = cli.run(["jobs", "watch", drained_job], drained_tenant, lb)
    # Exit 3: the design ran to its time budget, honestly not converged; it finished all the same.
    check(watched.returncode in (0, 3), f"the drained job: exit {watched.returncode}: {watched.stderr[-400:]}")
    attempts = cli.json(["jobs", "show", drained_job], drained_tenant, lb)["attempts"]
    check(attempts == 2, f"the drained job ran {attempts} time(s), 2 expected (interrupted, then again)")
    with http_request(f"http://127.0.0.1:{balancer.http_port}/api/v1/jobs/{drained_job}/files/report.json",
                      TOKENS[drained_tenant]) as reply:
        report = json.loads(reply.read())
    check(report.get("resumed_from_iteration", 0) >= 1,
          f"the drained design started over instead of resuming: resumed_from_iteration "
          f"{report.get('resumed_from_iteration')}")
    print(f"phase 3: the drained design resumed from iteration {report['resumed_from_iteration']}", flush=True)

    # 4. The HTTP gateway through the balancer: same shard as gRPC, SSE events, a file download.
    web = f"http://127.0.0.1:{balancer.http_port}/api/v1"
    for tenant in TENANTS:
        streamed = tenant == TENANTS[-1]  # its job is larger, so progress events arrive while it runs
        with open(large if streamed else small, "rb") as f:
            body = {"spec": {"simulate": {"rest_mesh": {"data": base64.b64encode(f.read()).decode(),
                                                        "format": "MESH_FORMAT_OBJ"},
                                          "material": {"name": "latex"}, "thickness_mm": 0.5,
                                          "volume_ratio": 8.0 if streamed else 2.0}}}
        with http_request(f"{web}/jobs", TOKENS[tenant], json.dumps(body).encode()) as reply:
            job_id = json.loads(reply.read())["job"]["id"]
        submitted[job_id] = tenant
        expected_shard = home[tenant]
        check(shard_of(job_id) == expected_shard, f"{tenant}: HTTP job {job_id}, gRPC jobs on {expected_shard}")
        if not streamed:
            continue
        events, states = [], []
        with http_request(f"{web}/jobs/{job_id}/events", TOKENS[tenant]) as stream:
            check(stream.headers.get("Content-Type", "").startswith("text/event-stream"), "not an event stream")
            event = None
            for raw in stream:
                line = raw.decode().rstrip("\n")
                if line.startswith("event: "):
                    event = line[7:]
                elif line.startswith("data: "):
                    events.append(event)
                    if event == "job":
                        states.append(json.loads(line[6:]).get("state"))
                    if event == "end":
                        break
        check(events and events[-1] == "end" and states and states[-1] == "JOB_STATE_COMPLETED" and
              "JOB_STATE_RUNNING" in states,
              f"SSE events {events} states {states}")
        with http_request(f"{web}/jobs/{job_id}/files/inflated.obj", TOKENS[tenant]) as reply:
            obj = reply.read().decode()
            disposition = reply.headers.get("Content-Disposition", "")
        vertices = sum(1 for line in obj.splitlines() if line.startswith("v "))
        check(vertices == 10242 and "attachment" in disposition, f"download: {vertices} vertices, {disposition!r}")
        print(f"phase 4: HTTP through the balancer: {len(events)} SSE events, inflated.obj {len(obj)} bytes",
              flush=True)
    for tenant in TENANTS:  # everything finished before the stores are read
        wait_until(lambda: all(j["state"] == "JOB_STATE_COMPLETED" for j in cli.listed(tenant, lb).values()), 60,
                   f"{tenant}'s last jobs")
    return submitted


def measure(cli, shards, balancer, small):
    """SubmitJob latency and throughput of tiny jobs, through the balancer and direct to one shard. Returns
    {job_id: tenant} of the jobs it submitted."""
    import grpc
    tenant = TENANTS[1]
    home = shard_of(next(iter(cli.listed(tenant, balancer.grpc))))
    direct = next(s for s in shards if s.name == home).grpc
    sys.path.insert(0, os.environ.get("BALLOON_PYTHON_STUBS", ""))
    from balloon.v1 import balloon_pb2
    request = balloon_pb2.SubmitJobRequest()
    with open(small, "rb") as f:
        request.spec.simulate.rest_mesh.data = f.read()
    request.spec.simulate.rest_mesh.format = balloon_pb2.MESH_FORMAT_OBJ
    request.spec.simulate.material.name = "latex"
    request.spec.simulate.thickness_mm = 0.5
    request.spec.simulate.volume_ratio = 1.2
    metadata = [("authorization", f"Bearer {TOKENS[tenant]}")]
    submitted = {}
    # Alternated twice: on a shared machine the first round also measures warm-up and neighbours.
    for label, address in (("direct", direct), ("balancer", balancer.grpc)) * 2:
        with grpc.insecure_channel(address) as channel:
            submit = channel.unary_unary("/balloon.v1.BalloonService/SubmitJob",
                                         request_serializer=lambda m: m.SerializeToString(),
                                         response_deserializer=balloon_pb2.SubmitJobResponse.FromString)
            get = channel.unary_unary("/balloon.v1.BalloonService/GetJob",
                                      request_serializer=lambda m: m.SerializeToString(),
                                      response_deserializer=balloon_pb2.Job.FromString)
            submitted[submit(request, metadata=metadata).job.id] = tenant  # warms the connection
            latencies, ids = [], []
            begin = time.time()
            for _ in range(40):
                t0 = time.perf_counter()
                ids.append(submit(request, metadata=metadata).job.id)
                latencies.append(time.perf_counter() - t0)
            for job_id in ids:
                while get(balloon_pb2.GetJobRequest(job_id=job_id), metadata=metadata).state != \
                        balloon_pb2.JOB_STATE_COMPLETED:
                    time.sleep(0.02)
            elapsed = time.time() - begin
            latencies.sort()
            print(f"measure {label}: SubmitJob median {1000 * latencies[len(latencies) // 2]:.2f} ms, "
                  f"p90 {1000 * latencies[int(0.9 * len(latencies))]:.2f} ms; 40 jobs in {elapsed:.2f} s = "
                  f"{40 / elapsed:.1f} jobs/s", flush=True)
            submitted.update({job_id: tenant for job_id in ids})
    return submitted


if __name__ == "__main__":
    sys.exit(main())
