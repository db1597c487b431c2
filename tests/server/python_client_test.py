#!/usr/bin/env python3
"""A client written against proto/balloon/v1/balloon.proto alone, in Python (Debian's python3-grpcio and
python3-protobuf; stubs from `protoc --python_out`, calls through grpc's generic channel methods since
grpc_tools is not packaged). Starts a balloon-server on an ephemeral port and runs a job end to end.

Usage: python_client_test.py BALLOON_SERVER_BINARY
"""
import math
import os
import subprocess
import sys
import tempfile

import grpc
from balloon.v1 import balloon_pb2 as pb

SERVICE = "/balloon.v1.BalloonService/"


def icosahedron_obj(radius_mm):
    """The 12-vertex icosahedron (outward faces) as OBJ text, coordinates in mm."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    vertices = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    scale = radius_mm / math.sqrt(1 + t * t)
    lines = ["v %.12g %.12g %.12g" % (x * scale, y * scale, z * scale) for x, y, z in vertices]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    return ("\n".join(lines) + "\n").encode()


def main():
    server_binary = sys.argv[1]
    with tempfile.TemporaryDirectory() as scratch:
        server = subprocess.Popen(
            [server_binary, "--listen", "127.0.0.1:0", "--db", os.path.join(scratch, "jobs.db"), "--workers", "1",
             "--quiet"], stdout=subprocess.PIPE, text=True)
        try:
            line = server.stdout.readline()
            assert "listening on 127.0.0.1:" in line, line
            port = int(line.split("listening on 127.0.0.1:")[1].split()[0])
            channel = grpc.insecure_channel("127.0.0.1:%d" % port)
            grpc.channel_ready_future(channel).result(timeout=10)

            def unary(method, request_type, response_type):
                return channel.unary_unary(SERVICE + method, request_serializer=request_type.SerializeToString,
                                           response_deserializer=response_type.FromString)

            submit = unary("SubmitJob", pb.SubmitJobRequest, pb.SubmitJobResponse)
            get_result = unary("GetResult", pb.GetResultRequest, pb.JobResult)
            list_materials = unary("ListMaterials", pb.ListMaterialsRequest, pb.ListMaterialsResponse)
            watch = channel.unary_stream(SERVICE + "WatchJob", request_serializer=pb.WatchJobRequest.SerializeToString,
                                         response_deserializer=pb.JobEvent.FromString)

            names = [m.name for m in list_materials(pb.ListMaterialsRequest(), timeout=10).materials]
            assert "latex" in names and "silicone" in names, names

            request = pb.SubmitJobRequest(spec=pb.JobSpec(simulate=pb.SimulateJob(
                rest_mesh=pb.MeshFile(data=icosahedron_obj(10.0), format=pb.MESH_FORMAT_OBJ),
                material=pb.MaterialRef(spec="neo-hookean:mu=0.3"), thickness_mm=0.5, volume_ratio=2.0)))
            job = submit(request, timeout=10).job
            assert job.id.startswith("j-") and job.state == pb.JOB_STATE_QUEUED, job

            events = list(watch(pb.WatchJobRequest(job_id=job.id), timeout=60))
            assert events, "no events"
            assert events[-1].state == pb.JOB_STATE_COMPLETED, events[-1]
            assert events[-1].converged

            result = get_result(pb.GetResultRequest(job_id=job.id, format=pb.MESH_FORMAT_OBJ), timeout=10)
            vertices = [l for l in result.inflated_mesh.data.decode().splitlines() if l.startswith("v ")]
            assert len(vertices) == 12, len(vertices)
            # The report is typed (SimulateReport), no JSON to parse.
            assert result.WhichOneof("report") == "simulate_report", result.WhichOneof("report")
            report = result.simulate_report
            assert report.converged is True
            assert abs(report.volume_ratio - 2.0) < 1e-6, report.volume_ratio
            assert report.vertices == 12

            try:
                submit(pb.SubmitJobRequest(spec=pb.JobSpec(simulate=pb.SimulateJob(
                    rest_mesh=pb.MeshFile(data=b"junk", format=pb.MESH_FORMAT_OBJ),
                    material=pb.MaterialRef(name="latex"), volume_ratio=2.0))), timeout=10)
                raise AssertionError("garbage mesh accepted")
            except grpc.RpcError as error:
                assert error.code() == grpc.StatusCode.INVALID_ARGUMENT, error
            print("python client: job %s completed, %d events, pressure %.4g kPa" %
                  (job.id, len(events), report.pressure_kpa))
            channel.close()
        finally:
            server.terminate()
            server.wait(timeout=20)
    return 0


if __name__ == "__main__":
    sys.exit(main())
