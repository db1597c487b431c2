#!/usr/bin/env python3
"""Offline check of deploy/kubernetes/ (no cluster here): parses every manifest with Debian's python3-yaml and
asserts the structure and the field names the deployment relies on. Not a schema validation.

  kubernetes_manifests_test.py REPO_ROOT
Exits 77 (ctest: skipped) without python3-yaml.
"""
import os
import re
import sys

try:
    import yaml
except ImportError:
    print("SKIP: python3-yaml is not installed (deploy/install-deps.sh installs it)")
    sys.exit(77)


def check(condition, message):
    if not condition:
        print(f"FAIL: {message}")
        sys.exit(1)


def main(root):
    kube = os.path.join(root, "deploy", "kubernetes")
    kustomization = yaml.safe_load(open(os.path.join(kube, "kustomization.yaml")))
    objects = {}
    for name in kustomization["resources"]:
        for doc in yaml.safe_load_all(open(os.path.join(kube, name))):
            check(doc and {"apiVersion", "kind", "metadata"} <= doc.keys(), f"{name}: a document without apiVersion/kind/metadata")
            objects[(doc["kind"], doc["metadata"]["name"])] = doc
    namespace = kustomization["namespace"]
    for (kind, name), doc in objects.items():
        check(doc["metadata"].get("namespace", namespace) == namespace or kind == "Namespace", f"{kind}/{name} namespace")

    shards = objects[("StatefulSet", "balloon")]
    check(shards["apiVersion"] == "apps/v1", "StatefulSet apiVersion")
    spec, pod = shards["spec"], shards["spec"]["template"]["spec"]
    labels = shards["spec"]["template"]["metadata"]["labels"]
    check(spec["selector"]["matchLabels"].items() <= labels.items(), "StatefulSet selector matches its pods")
    headless = objects[("Service", spec["serviceName"])]
    check(headless["spec"]["clusterIP"] == "None", "the StatefulSet's service is headless")
    check(headless["spec"]["selector"].items() <= labels.items(), "the headless service selects the shards")
    check(pod["securityContext"]["runAsNonRoot"] is True and pod["securityContext"]["runAsUser"] != 0, "non-root shards")

    (server,) = pod["containers"]
    args = server["args"]
    flag = lambda name: args[args.index(name) + 1]  # noqa: E731
    check(flag("--shard-name") == "$(POD_NAME)", "--shard-name is the pod name")
    env = {e["name"]: e for e in server["env"]}
    check(env["POD_NAME"]["valueFrom"]["fieldRef"]["fieldPath"] == "metadata.name", "POD_NAME from metadata.name")
    check(re.fullmatch(r"[a-z0-9-]{1,29}", shards["metadata"]["name"]), "pod names fit --shard-name (<= 32 chars)")
    ports = {p["name"]: p["containerPort"] for p in server["ports"]}
    check(flag("--listen") == f"0.0.0.0:{ports['grpc']}" and flag("--http") == f"0.0.0.0:{ports['http']}", "listen ports")
    for probe in ("readinessProbe", "livenessProbe"):
        check(server[probe]["grpc"]["port"] == ports["grpc"], f"{probe} is a gRPC health probe on the gRPC port")
    check(pod["terminationGracePeriodSeconds"] > float(flag("--drain-timeout")), "grace period above --drain-timeout")
    check(server["resources"]["requests"]["cpu"] == flag("--workers"), "cpu request = --workers")
    check("memory" in server["resources"]["requests"], "a memory request")

    mounts = {m["name"]: m["mountPath"] for m in server["volumeMounts"]}
    (claim,) = spec["volumeClaimTemplates"]
    check(claim["spec"]["accessModes"] == ["ReadWriteOnce"], "one claim per pod, ReadWriteOnce")
    check(flag("--db").startswith(mounts[claim["metadata"]["name"]] + "/"), "the SQLite file is on the pod's claim")
    volumes = {v["name"]: v for v in pod["volumes"]}
    secret = objects[("Secret", volumes["tokens"]["secret"]["secretName"])]
    token_key = os.path.basename(flag("--token-file"))
    check(os.path.dirname(flag("--token-file")) == mounts["tokens"], "--token-file is in the secret's mount")
    check(token_key in secret.get("stringData", {}) or token_key in secret.get("data", {}), "the secret holds the token file")

    pdbs = [doc for (kind, _), doc in objects.items() if kind == "PodDisruptionBudget"]
    check(any(p["spec"]["selector"]["matchLabels"].items() <= labels.items() and p["spec"].get("maxUnavailable") == 1
              for p in pdbs), "a PodDisruptionBudget lets one shard go at a time")

    # The balancer: the ConfigMap is deploy/loadbalancer/haproxy.cfg verbatim, every ${VAR} it uses is set,
    # and it names exactly the StatefulSet's pods.
    balancer = objects[("Deployment", "balloon-balancer")]
    bpod = balancer["spec"]["template"]["spec"]
    (haproxy,) = bpod["containers"]
    config_map = objects[("ConfigMap", next(v["configMap"]["name"] for v in bpod["volumes"] if "configMap" in v))]
    config = open(os.path.join(root, "deploy", "loadbalancer", "haproxy.cfg")).read()
    check(config_map["data"]["haproxy.cfg"] == config, "the ConfigMap differs from deploy/loadbalancer/haproxy.cfg")
    benv = {e["name"]: e["value"] for e in haproxy["env"]}
    used = set(re.findall(r"\$\{(\w+)\}", config))
    check(used == set(benv), f"environment {sorted(set(benv) ^ used)} differs from the config's variables")
    ids = re.findall(r"server shard(\d+) \"\$\{BALLOON_SHARD\1_GRPC\}\" id (\d+)", config)
    check(len(ids) == spec["replicas"], f"{len(ids)} gRPC shards in haproxy.cfg, {spec['replicas']} replicas")
    service = spec["serviceName"]
    for index, _ in ids:
        host = f"{shards['metadata']['name']}-{index}.{service}.{namespace}.svc.cluster.local"
        check(benv[f"BALLOON_SHARD{index}_GRPC"] == f"{host}:{ports['grpc']}", f"shard {index} gRPC address")
        check(benv[f"BALLOON_SHARD{index}_HTTP"] == f"{host}:{ports['http']}", f"shard {index} HTTP address")
    http_ids = re.findall(r"server shard(\d+) \"\$\{BALLOON_SHARD\1_HTTP\}\" id (\d+)", config)
    check(ids == http_ids, "both backends list the same shards with the same ids (one ring)")
    check(haproxy["args"][haproxy["args"].index("-f") + 1].startswith(
        next(m["mountPath"] for m in haproxy["volumeMounts"] if m["name"] == next(
            v["name"] for v in bpod["volumes"] if "configMap" in v))), "haproxy reads the ConfigMap")
    check(bpod["securityContext"]["runAsNonRoot"] is True, "non-root balancer")

    # The images the manifests name are the ones deploy/Dockerfile documents.
    dockerfile = open(os.path.join(root, "deploy", "Dockerfile")).read()
    for image in (server["image"], haproxy["image"]):
        check(f"-t {image}" in dockerfile, f"deploy/Dockerfile does not document building {image}")
    print(f"PASS: {len(objects)} Kubernetes objects parsed and cross-checked")


if __name__ == "__main__":
    main(sys.argv[1])
