#!/usr/bin/env python3
"""The deployment files under deploy/ (docs/DEPLOYMENT.md) agree with radiantd and with each other.

They cannot run here (no cluster, no systemd, no GPU), so this checks what can go wrong unseen:
every radiantd command line in them parses (`radiantd ARGS --help` exits 0 only when every flag
before --help exists and its value is valid), the probes and the drain use the daemon's endpoints and
outlast its timeouts, the memory limits cover the stores the flags bound, and the nginx ConfigMap is
deploy/nginx/radiant.conf with one upstream per daemon of the StatefulSet.
"""
import argparse
import re
import shlex
import subprocess
import sys
import unittest
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[3]
RADIANTD = None
BYTE_FLAGS = ("--max-scene-bytes", "--scene-cache-bytes", "--max-frame-bytes", "--max-decode-bytes")


def flag_values(argv):
    out = {}
    for i, a in enumerate(argv):
        if a.startswith("--"):
            out[a] = argv[i + 1] if i + 1 < len(argv) and not argv[i + 1].startswith("--") else True
    return out


def parses(argv):
    r = subprocess.run([RADIANTD] + argv + ["--help"], capture_output=True, text=True, timeout=30)
    return r.returncode, r.stderr.strip()


def quantity_bytes(q):
    units = {"Ki": 2**10, "Mi": 2**20, "Gi": 2**30, "Ti": 2**40, "K": 10**3, "M": 10**6, "G": 10**9}
    m = re.fullmatch(r"(\d+)([A-Za-z]*)", str(q))
    return int(m.group(1)) * units.get(m.group(2), 1)


def load(name):
    return list(yaml.safe_load_all((ROOT / "deploy" / "k8s" / name).read_text()))


def by_kind(docs, kind):
    found = [d for d in docs if d["kind"] == kind]
    assert len(found) == 1, f"expected one {kind}, found {len(found)}"
    return found[0]


class Kubernetes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon_docs = load("radiantd.yaml")
        cls.proxy_docs = load("nginx.yaml")
        cls.sts = by_kind(cls.daemon_docs, "StatefulSet")
        cls.pod = cls.sts["spec"]["template"]["spec"]
        cls.container = cls.pod["containers"][0]
        script = cls.container["args"][0]
        argv = shlex.split(script.replace('"d${HOSTNAME##*-}"', "d0"))
        cls.assertTrue(cls, argv[0] == "exec" and argv[1].endswith("/radiantd"), argv[:2])
        cls.argv = argv[2:]
        cls.flags = flag_values(cls.argv)

    def test_the_daemon_command_line_parses(self):
        code, err = parses(self.argv)
        self.assertEqual(code, 0, f"radiantd {' '.join(self.argv)} --help: {err}")
        for f in ("--daemon-id", "--cuda-device", "--host", "--port"):
            self.assertIn(f, self.flags)
        self.assertEqual(self.flags["--host"], "0.0.0.0")

    def test_one_gpu_per_daemon(self):
        res = self.container["resources"]
        self.assertEqual(res["limits"]["nvidia.com/gpu"], 1)
        self.assertEqual(self.flags["--cuda-device"], "0")  # the pod's one GPU

    def test_memory_limit_covers_the_bounded_stores(self):
        bound = sum(int(self.flags[f]) for f in BYTE_FLAGS)
        limit = quantity_bytes(self.container["resources"]["limits"]["memory"])
        self.assertGreaterEqual(limit, bound + 2**30, f"limit {limit} B, stores {bound} B + 1 GiB for the renderer")

    def test_probes_use_ready_and_health(self):
        port = int(self.flags["--port"])
        self.assertEqual(self.container["ports"][0]["containerPort"], port)
        self.assertEqual(self.container["readinessProbe"]["httpGet"]["path"], "/v1/ready")
        self.assertEqual(self.container["startupProbe"]["httpGet"]["path"], "/v1/ready")
        self.assertEqual(self.container["livenessProbe"]["httpGet"]["path"], "/v1/health")

    def test_the_drain_outlasts_the_daemons_timeouts(self):
        pre = " ".join(self.container["lifecycle"]["preStop"]["exec"]["command"])
        self.assertIn("kill -TERM 1", pre)
        self.assertIn("while kill -0 1", pre)  # waits until the daemon has exited
        need = float(self.flags["--request-timeout"]) + float(self.flags["--shutdown-grace"])
        self.assertGreater(self.pod["terminationGracePeriodSeconds"], need)

    def test_the_proxy_config_is_the_shipped_one_with_every_daemon(self):
        cm = by_kind(self.proxy_docs, "ConfigMap")["data"]
        self.assertEqual(cm["radiant.conf"], (ROOT / "deploy" / "nginx" / "radiant.conf").read_text(),
                         "the ConfigMap's radiant.conf differs from deploy/nginx/radiant.conf")
        replicas, svc, port = self.sts["spec"]["replicas"], self.sts["spec"]["serviceName"], self.flags["--port"]
        headless = [d for d in self.daemon_docs if d["kind"] == "Service"][0]
        self.assertEqual(headless["metadata"]["name"], svc)
        self.assertEqual(headless["spec"]["clusterIP"], "None")
        expected = [f"radiantd-{i}.{svc}:{port}" for i in range(replicas)]
        self.assertEqual(re.findall(r"server (\S+)", cm["radiant.fleet"]), expected)
        owners = dict(re.findall(r"^\s+(d\d+) (radiant_d\d+);", cm["radiant.daemons"], re.M))
        self.assertEqual(owners, {f"d{i}": f"radiant_d{i}" for i in range(replicas)})
        for i in range(replicas):
            self.assertRegex(cm["radiant.daemons"], rf"upstream radiant_d{i} {{[^}}]*server {re.escape(expected[i])}")
        listen = re.search(r"listen (\d+);", cm["radiant.conf"]).group(1)
        proxy = by_kind(self.proxy_docs, "Deployment")["spec"]["template"]["spec"]["containers"][0]
        self.assertEqual(str(proxy["ports"][0]["containerPort"]), listen)
        mounts = {m["mountPath"] for m in proxy["volumeMounts"]}
        self.assertEqual(mounts, {"/etc/nginx/conf.d/radiant.conf", "/etc/nginx/radiant.fleet", "/etc/nginx/radiant.daemons"})


class Systemd(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        text = (ROOT / "deploy" / "systemd" / "radiantd@.service").read_text().replace("\\\n", " ")
        cls.keys = {}
        for line in text.splitlines():
            if "=" in line and not line.startswith("#"):
                k, v = line.split("=", 1)
                cls.keys[k.strip()] = v.strip()
        argv = shlex.split(cls.keys["ExecStart"].replace("%i", "0"))
        cls.argv = argv[1:]
        cls.flags = flag_values(cls.argv)

    def test_the_daemon_command_line_parses(self):
        code, err = parses(self.argv)
        self.assertEqual(code, 0, f"radiantd {' '.join(self.argv)} --help: {err}")
        self.assertEqual(self.flags["--daemon-id"], "d0")
        self.assertEqual(self.flags["--cuda-device"], "0")

    def test_stop_timeout_and_memory_cover_the_flags(self):
        self.assertEqual(self.keys["KillSignal"], "SIGTERM")
        need = float(self.flags["--request-timeout"]) + float(self.flags["--shutdown-grace"])
        self.assertGreater(float(self.keys["TimeoutStopSec"]), need)
        bound = sum(int(self.flags[f]) for f in BYTE_FLAGS)
        self.assertGreaterEqual(quantity_bytes(self.keys["MemoryMax"]), bound + 2**30)


class Nginx(unittest.TestCase):
    def test_the_example_daemon_files_agree(self):
        d = ROOT / "deploy" / "nginx"
        fleet = re.findall(r"^server (\S+)", (d / "radiant.fleet").read_text(), re.M)
        daemons = (d / "radiant.daemons").read_text()
        owners = re.findall(r"^\s+(d\d+) (radiant_d\d+);", daemons, re.M)
        self.assertEqual(len(fleet), len(owners))
        for i, addr in enumerate(fleet):
            self.assertRegex(daemons, rf"upstream radiant_d{i} {{ server {re.escape(addr)};")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--radiantd", required=True)
    args, rest = ap.parse_known_args()
    RADIANTD = args.radiantd
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
