#!/usr/bin/env python3
"""The deployment files, checked as far as this machine allows:
Kubernetes manifests and compose are parsed (PyYAML) and their required keys
checked, including that the probes are native gRPC probes on the gRPC port
and that the grace period outlasts the server's drain; every SURFINSPECT_*
variable they set is one that surfinspectd --help lists, and the ConfigMap
and the systemd env file really start a server; the Dockerfile is two-stage
with the README's own build commands, and its runtime package list covers
every shared library the built binaries need (dpkg); the systemd units pass
`systemd-analyze verify` when it is installed.

Run with Debian's /usr/bin/python3 (python3-yaml).
usage: deploy_files_test.py SOURCE_DIR BIN_DIR [unittest args]
"""
import glob
import os
import re
import shlex
import shutil
import socket
import subprocess
import sys
import tempfile
import unittest

import yaml

SRC = BIN = None
GRPC_PORT, METRICS_PORT = 50051, 9464
HEALTH_SERVICE = "surfinspect.v1.InspectionService"
# What the image ships: the CLI and the agent run the CAD worker beside them.
BINARIES = ("surfinspectd", "surfinspect", "cell-agent", "surfinspect-cad-worker")


def load_yaml(*parts):
    with open(os.path.join(SRC, *parts)) as f:
        return [d for d in yaml.safe_load_all(f) if d is not None]


def server_env_vars():
    """SURFINSPECT_* variables that surfinspectd reads, from its --help."""
    out = subprocess.run([os.path.join(BIN, "surfinspectd"), "--help"], capture_output=True, text=True).stdout
    names = set(re.findall(r"Env:(SURFINSPECT_\w+)", out))
    assert "SURFINSPECT_DRAIN_SECONDS" in names, out
    return names


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server_with_env(env_vars):
    """Starts surfinspectd with these SURFINSPECT_* variables, on free
    loopback ports, and returns (process, target) once it listens."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("SURFINSPECT_")}
    env.update(env_vars)
    env["SURFINSPECT_LISTEN"] = "127.0.0.1:0"
    env["SURFINSPECT_METRICS_LISTEN"] = f"127.0.0.1:{free_port()}"
    proc = subprocess.Popen([os.path.join(BIN, "surfinspectd")], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    return proc, line.split()[-1] if "listening on" in line else None


def stop(proc):
    """SIGKILL: the drain is tested elsewhere, and stopping the metrics
    listener gracefully takes ~2 s."""
    if proc.poll() is None:
        proc.kill()
    return proc.communicate(timeout=30)


def dockerfile_instructions():
    """[(stage index, KEYWORD, arguments)] with continuation lines joined."""
    with open(os.path.join(SRC, "Dockerfile")) as f:
        lines = f.read().splitlines()
    out, buf, stage = [], "", -1
    for line in lines:
        if line.strip().startswith("#") or not line.strip():
            continue
        buf += line.rstrip()
        if buf.endswith("\\"):
            buf = buf[:-1] + " "
            continue
        keyword, _, args = buf.strip().partition(" ")
        keyword = keyword.upper()
        if keyword == "FROM":
            stage += 1
        out.append((stage, keyword, " ".join(args.split())))
        buf = ""
    return out


class KubernetesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.docs = {}
        for path in sorted(glob.glob(os.path.join(SRC, "deploy", "k8s", "*.yaml"))):
            for d in load_yaml(path):
                if "kind" in d and d.get("apiVersion") != "kustomize.config.k8s.io/v1beta1":
                    cls.docs.setdefault(d["kind"], []).append((os.path.basename(path), d))
        cls.deployment = cls.one("Deployment")
        cls.pod = cls.deployment["spec"]["template"]["spec"]
        cls.container = cls.pod["containers"][0]
        cls.config = cls.one("ConfigMap")

    @classmethod
    def one(cls, kind):
        found = [d for f, d in cls.docs.get(kind, []) if f != "secret.example.yaml"]
        assert len(found) == 1, f"{kind}: {len(found)} documents"
        return found[0]

    def test_kustomization_lists_every_manifest_but_no_secret_values(self):
        k = load_yaml("deploy", "k8s", "kustomization.yaml")[0]
        self.assertEqual(sorted(k["resources"]),
                         ["configmap.yaml", "deployment.yaml", "hpa.yaml", "pdb.yaml", "service.yaml"])
        self.assertNotIn("secret.example.yaml", k["resources"])
        for r in k["resources"]:
            self.assertTrue(os.path.exists(os.path.join(SRC, "deploy", "k8s", r)), r)

    def test_deployment_replicas_resources_and_security(self):
        self.assertEqual(self.deployment["spec"]["replicas"], 3)
        labels = self.deployment["spec"]["template"]["metadata"]["labels"]
        self.assertLessEqual(self.deployment["spec"]["selector"]["matchLabels"].items(), labels.items())
        res = self.container["resources"]
        for section in ("requests", "limits"):
            self.assertIn("cpu", res[section])
            self.assertIn("memory", res[section])
        # One TBB arena of SURFINSPECT_THREADS cores: match the CPU request.
        self.assertEqual(str(res["requests"]["cpu"]), self.config["data"]["SURFINSPECT_THREADS"])
        self.assertTrue(self.pod["securityContext"]["runAsNonRoot"])
        self.assertNotEqual(self.pod["securityContext"]["runAsUser"], 0)
        self.assertFalse(self.container["securityContext"]["allowPrivilegeEscalation"])
        ports = {p["name"]: p["containerPort"] for p in self.container["ports"]}
        self.assertEqual(ports, {"grpc": GRPC_PORT, "metrics": METRICS_PORT})

    def test_probes_are_native_grpc_probes_on_the_grpc_port(self):
        for probe in ("readinessProbe", "livenessProbe"):
            p = self.container[probe]
            self.assertEqual(set(p) & {"grpc", "exec", "httpGet", "tcpSocket"}, {"grpc"}, probe)
            self.assertEqual(p["grpc"]["port"], GRPC_PORT, probe)
        # Readiness asks for the inspection service by the name the server
        # registers with grpc.health.v1.
        self.assertEqual(self.container["readinessProbe"]["grpc"]["service"], HEALTH_SERVICE)
        with open(os.path.join(SRC, "server", "run_server.cpp")) as f:
            self.assertIn(f'SetServingStatus("{HEALTH_SERVICE}", true)', f.read())

    def test_grace_period_outlasts_the_drain(self):
        drain = float(self.config["data"]["SURFINSPECT_DRAIN_SECONDS"])
        self.assertGreater(self.pod["terminationGracePeriodSeconds"], drain)
        # Liveness must not restart a pod that is draining (health is
        # NOT_SERVING for the whole drain).
        live = self.container["livenessProbe"]
        self.assertGreater(live["periodSeconds"] * live["failureThreshold"], drain)

    def test_configmap_is_used_and_sets_only_real_server_flags(self):
        refs = [e["configMapRef"]["name"] for e in self.container["envFrom"]]
        self.assertEqual(refs, [self.config["metadata"]["name"]])
        known = server_env_vars()
        env = {e["name"]: e.get("value") for e in self.container.get("env", [])}
        for name in list(self.config["data"]) + list(env):
            self.assertIn(name, known)
        self.assertEqual(self.config["data"]["SURFINSPECT_LISTEN"], f"0.0.0.0:{GRPC_PORT}")
        self.assertEqual(self.config["data"]["SURFINSPECT_METRICS_LISTEN"], f"0.0.0.0:{METRICS_PORT}")
        # The values parse: a server started with them serves.
        proc, target = start_server_with_env(self.config["data"])
        try:
            self.assertIsNotNone(target, proc.stderr.read() if proc.poll() is not None else "")
            health = subprocess.run([os.path.join(BIN, "surfinspect"), "health", "--server", target,
                                     "--service", HEALTH_SERVICE], capture_output=True, text=True)
            self.assertEqual(health.returncode, 0, health.stderr)
            self.assertIn("SERVING", health.stdout)
        finally:
            _, err = stop(proc)
        self.assertIn('"level":"info"', err)  # SURFINSPECT_JSON_LOGS=true took effect

    def test_secrets_are_referenced_for_the_token_and_tls(self):
        volumes = {v["name"]: v for v in self.pod["volumes"]}
        mounts = {m["name"]: m["mountPath"] for m in self.container["volumeMounts"]}
        secrets = {v["secret"]["secretName"]: name for name, v in volumes.items() if "secret" in v}
        self.assertEqual(set(secrets), {"surfinspect-token", "surfinspect-tls"})
        token_mount = mounts[secrets["surfinspect-token"]]
        env = {e["name"]: e.get("value") for e in self.container["env"]}
        self.assertTrue(env["SURFINSPECT_AUTH_TOKEN_FILE"].startswith(token_mount + "/"))
        examples = {d["metadata"]["name"]: d for f, d in self.docs["Secret"] if f == "secret.example.yaml"}
        self.assertEqual(set(examples), set(secrets))
        self.assertIn(os.path.basename(env["SURFINSPECT_AUTH_TOKEN_FILE"]),
                      examples["surfinspect-token"]["stringData"])

    def test_tls_overlay_swaps_the_probes_for_exec_health_checks(self):
        k = load_yaml("deploy", "k8s", "tls", "kustomization.yaml")[0]
        self.assertEqual(k["resources"], [".."])
        patch = load_yaml("deploy", "k8s", "tls", k["patches"][0]["path"])[0]
        c = patch["spec"]["template"]["spec"]["containers"][0]
        self.assertEqual(c["name"], self.container["name"])
        tls_mount = {m["name"]: m["mountPath"] for m in self.container["volumeMounts"]}["tls"]
        env = {e["name"]: e["value"] for e in c["env"]}
        for name in ("SURFINSPECT_TLS_CERT", "SURFINSPECT_TLS_KEY"):
            self.assertTrue(env[name].startswith(tls_mount + "/"), name)
        for probe in ("readinessProbe", "livenessProbe"):
            self.assertIsNone(c[probe]["grpc"], f"{probe}: the plaintext gRPC probe must be removed")
            cmd = c[probe]["exec"]["command"]
            self.assertEqual(cmd[:4], ["surfinspect", "health", "--server", f"127.0.0.1:{GRPC_PORT}"])
            self.assertTrue(cmd[cmd.index("--tls-ca") + 1].startswith(tls_mount + "/"))

    def test_headless_service_for_client_side_balancing(self):
        svc = self.one("Service")
        self.assertEqual(svc["spec"]["clusterIP"], "None")
        labels = self.deployment["spec"]["template"]["metadata"]["labels"]
        self.assertLessEqual(svc["spec"]["selector"].items(), labels.items())
        ports = {p["name"]: p for p in svc["spec"]["ports"]}
        self.assertEqual(ports["grpc"]["port"], GRPC_PORT)
        self.assertEqual(ports["grpc"]["targetPort"], "grpc")

    def test_hpa_on_cpu_and_pdb(self):
        hpa = self.one("HorizontalPodAutoscaler")
        self.assertEqual(hpa["apiVersion"], "autoscaling/v2")
        self.assertEqual(hpa["spec"]["scaleTargetRef"]["kind"], "Deployment")
        self.assertEqual(hpa["spec"]["scaleTargetRef"]["name"], self.deployment["metadata"]["name"])
        self.assertEqual(hpa["spec"]["minReplicas"], self.deployment["spec"]["replicas"])
        self.assertGreater(hpa["spec"]["maxReplicas"], hpa["spec"]["minReplicas"])
        cpu = [m for m in hpa["spec"]["metrics"] if m["type"] == "Resource" and m["resource"]["name"] == "cpu"]
        self.assertEqual(len(cpu), 1)
        self.assertEqual(cpu[0]["resource"]["target"]["type"], "Utilization")
        pdb = self.one("PodDisruptionBudget")
        self.assertEqual(pdb["apiVersion"], "policy/v1")
        labels = self.deployment["spec"]["template"]["metadata"]["labels"]
        self.assertLessEqual(pdb["spec"]["selector"]["matchLabels"].items(), labels.items())
        self.assertLess(pdb["spec"]["minAvailable"], self.deployment["spec"]["replicas"])
        self.assertGreaterEqual(pdb["spec"]["minAvailable"], 1)


class ComposeTest(unittest.TestCase):
    def setUp(self):
        self.compose = load_yaml("deploy", "compose.yaml")[0]
        self.services = self.compose["services"]

    def test_two_servers_and_an_agent_balancing_over_both(self):
        servers = {n: s for n, s in self.services.items() if "entrypoint" not in s and "command" not in s}
        self.assertEqual(len(servers), 2, list(self.services))
        agent = self.services["cell-agent"]
        for s in list(servers.values()) + [agent]:
            self.assertEqual(s["image"], "surfinspect:0.1.0")
        ips = sorted(s["networks"]["cell"]["ipv4_address"] for s in servers.values())
        target = agent["environment"]["TARGET"]
        self.assertEqual(target, "ipv4:" + ",".join(f"{ip}:{GRPC_PORT}" for ip in ips))
        script = agent["command"][0]
        self.assertIn('--server "$$TARGET"', script)  # $$: compose passes a literal $ to the shell
        for step in ("surfinspect demo-cell", "cell-agent calibrate", "cell-agent run"):
            self.assertIn(step, script)
        for name in servers:
            self.assertEqual(agent["depends_on"][name]["condition"], "service_healthy")
        drain = float(servers[sorted(servers)[0]]["environment"]["SURFINSPECT_DRAIN_SECONDS"])
        for s in servers.values():
            self.assertGreater(int(s["stop_grace_period"].rstrip("s")), drain)
            self.assertLessEqual(set(s["environment"]), server_env_vars())
        subnet = self.compose["networks"]["cell"]["ipam"]["config"][0]["subnet"]
        self.assertTrue(all(ip.startswith(subnet.rsplit(".", 1)[0] + ".") for ip in ips))
        self.assertEqual(servers[sorted(servers)[0]]["build"]["dockerfile"], "Dockerfile")
        self.assertTrue(os.path.exists(os.path.join(SRC, "deploy", servers[sorted(servers)[0]]["build"]["context"],
                                                    "Dockerfile")))


class DockerfileTest(unittest.TestCase):
    def setUp(self):
        self.ins = dockerfile_instructions()
        self.stages = [args for _, k, args in self.ins if k == "FROM"]

    def stage(self, i):
        return [(k, a) for s, k, a in self.ins if s == i]

    def test_multi_stage_on_bookworm_and_bookworm_slim(self):
        self.assertEqual(self.stages, ["debian:bookworm AS build", "debian:bookworm-slim AS runtime"])

    def test_build_steps_are_the_readme_commands(self):
        runs = [a for k, a in self.stage(0) if k == "RUN"]
        self.assertTrue(runs[0].startswith("./run deps"), runs)
        self.assertTrue(runs[1].startswith("./run build"), runs)
        with open(os.path.join(SRC, "README.md")) as f:
            readme = f.read()
        self.assertIn("./run deps", readme)
        self.assertIn("./run build", readme)

    def test_runtime_user_ports_healthcheck_and_binaries(self):
        rt = self.stage(1)
        user = [a for k, a in rt if k == "USER"]
        self.assertEqual(len(user), 1)
        self.assertNotIn(user[0].split(":")[0], ("0", "root"))
        # The same uid as the Kubernetes securityContext.
        dep = [d for d in load_yaml("deploy", "k8s", "deployment.yaml") if d["kind"] == "Deployment"][0]
        self.assertEqual(int(user[0].split(":")[0]), dep["spec"]["template"]["spec"]["securityContext"]["runAsUser"])
        exposed = {int(p) for k, a in rt if k == "EXPOSE" for p in a.split()}
        self.assertEqual(exposed, {GRPC_PORT, METRICS_PORT})
        health = [a for k, a in rt if k == "HEALTHCHECK"]
        self.assertEqual(len(health), 1)
        self.assertRegex(health[0], r'CMD \["surfinspect", "health", "--server", "127\.0\.0\.1:50051"\]')
        copied = " ".join(a for k, a in rt if k == "COPY" and a.startswith("--from=build"))
        for b in BINARIES:
            self.assertIn(f"/src/build/bin/{b} ", copied + " ")
        self.assertEqual([a for k, a in rt if k == "ENTRYPOINT"], ['["surfinspectd"]'])
        with open(os.path.join(SRC, ".dockerignore")) as f:
            ignored = f.read().split()
        for d in ("build", ".git"):
            self.assertIn(d, ignored)

    def runtime_packages(self):
        runs = " ".join(a for k, a in self.stage(1) if k == "RUN")
        words = shlex.split(runs.split("--no-install-recommends", 1)[1].split("&&")[0])
        return set(words)

    @unittest.skipUnless(shutil.which("dpkg") and shutil.which("ldd"), "needs dpkg and ldd (Debian)")
    @unittest.skipIf(os.environ.get("SURFINSPECT_SANITIZED") == "1",
                     "a sanitized build links libraries the release image never ships")
    def test_runtime_packages_cover_every_library_the_binaries_need(self):
        packages = self.runtime_packages()
        essential = {"libc6", "libgcc-s1"}  # in every Debian image
        needs = {}  # resolved library path -> (binary, soname)
        for b in BINARIES:
            path = os.path.join(BIN, b)
            needed = re.findall(r"\(NEEDED\)\s+Shared library: \[(.+?)\]",
                                subprocess.run(["readelf", "-d", path], capture_output=True, text=True).stdout)
            self.assertTrue(needed, b)
            resolved = dict(re.findall(r"^\s*(\S+) => (\S+)", subprocess.run(
                ["ldd", path], capture_output=True, text=True).stdout, re.M))
            for soname in needed:
                # The dynamic loader (named by code from static archives that
                # uses thread-local storage) is libc6's; ldd lists it by path.
                if soname.startswith("ld-linux"):
                    continue
                needs[os.path.realpath(resolved[soname])] = (b, soname)
        # One dpkg -S for all; with merged /usr dpkg may know the /lib path.
        queries = sorted(needs) + [p.replace("/usr/lib/", "/lib/", 1) for p in sorted(needs)]
        owners = {}
        for line in subprocess.run(["dpkg", "-S", *queries], capture_output=True, text=True).stdout.splitlines():
            package, _, lib = line.partition(": ")
            owners[lib.replace("/lib/", "/usr/lib/", 1) if lib.startswith("/lib/") else lib] = \
                package.split(":")[0]
        for lib, (b, soname) in sorted(needs.items()):
            self.assertIn(lib, owners, f"{b}: {soname} ({lib}) belongs to no package")
            self.assertIn(owners[lib], packages | essential, f"{b} needs {soname} from {owners[lib]}")


class SystemdTest(unittest.TestCase):
    @staticmethod
    def parse(name):
        sections, current = {}, None
        with open(os.path.join(SRC, "deploy", "systemd", name)) as f:
            text = f.read().replace("\\\n", " ")
        for line in text.splitlines():
            line = line.strip()
            if not line or line[0] in "#;":
                continue
            if line.startswith("["):
                current = sections.setdefault(line.strip("[]"), {})
            else:
                k, _, v = line.partition("=")
                current.setdefault(k, []).append(v)
        return sections

    @staticmethod
    def env_file(name):
        values = {}
        with open(os.path.join(SRC, "deploy", "systemd", name)) as f:
            for line in f:
                if line.strip() and not line.startswith("#"):
                    k, _, v = line.strip().partition("=")
                    values[k] = v
        return values

    def check_hardening(self, service):
        for key, value in (("NoNewPrivileges", "yes"), ("ProtectSystem", "strict"), ("ProtectHome", "yes"),
                           ("PrivateTmp", "yes"), ("PrivateDevices", "yes"), ("CapabilityBoundingSet", ""),
                           ("RestrictAddressFamilies", "AF_INET AF_INET6 AF_UNIX"),
                           ("SystemCallFilter", "@system-service")):
            self.assertEqual(service.get(key), [value], key)
        self.assertNotIn(service["User"][0], ("root", "0"))
        self.assertEqual(service["KillSignal"], ["SIGTERM"])

    def test_server_unit(self):
        s = self.parse("surfinspectd.service")["Service"]
        self.assertEqual(s["ExecStart"], ["/usr/local/bin/surfinspectd"])
        self.assertEqual(s["EnvironmentFile"], ["/etc/surfinspect/surfinspectd.env"])
        self.check_hardening(s)
        env = self.env_file("surfinspectd.env")
        self.assertLessEqual(set(env), server_env_vars())
        self.assertGreater(int(s["TimeoutStopSec"][0]), float(env["SURFINSPECT_DRAIN_SECONDS"]))
        self.assertIn("Environment", s)
        self.assertEqual(s["Environment"], ["SURFINSPECT_AUTH_TOKEN_FILE=%d/token"])
        self.assertEqual(s["LoadCredential"], ["token:/etc/surfinspect/token"])
        # The env file's values start a server.
        proc, target = start_server_with_env(env)
        try:
            self.assertIsNotNone(target)
            health = subprocess.run([os.path.join(BIN, "surfinspect"), "health", "--server", target],
                                    capture_output=True, text=True)
            self.assertEqual(health.returncode, 0, health.stderr)
        finally:
            stop(proc)

    def test_agent_unit(self):
        s = self.parse("cell-agent.service")["Service"]
        self.check_hardening(s)
        argv = s["ExecStart"][0].split()
        self.assertEqual(argv[:2], ["/usr/local/bin/cell-agent", "run"])
        env = self.env_file("cell-agent.env")
        for flag, var in (("--cell", "CELL"), ("--server", "SURFINSPECT_SERVER"), ("--inbox", "INBOX"),
                          ("--results", "RESULTS"), ("--archive", "ARCHIVE"), ("--quarantine", "QUARANTINE")):
            self.assertEqual(argv[argv.index(flag) + 1], "${%s}" % var)
            self.assertIn(var, env)
        state = "/var/lib/" + s["StateDirectory"][0]
        for var in ("INBOX", "RESULTS", "ARCHIVE", "QUARANTINE", "CELL"):
            self.assertTrue(env[var].startswith(state + "/"), f"{var} must be writable under ProtectSystem=strict")
        self.assertEqual(s["EnvironmentFile"], ["/etc/surfinspect/cell-agent.env"])
        # The agent accepts every flag the unit passes.
        help_text = subprocess.run([os.path.join(BIN, "cell-agent"), "run", "--help"], capture_output=True,
                                   text=True).stdout
        for flag in (a for a in argv if a.startswith("--")):
            self.assertIn(flag, help_text)

    @unittest.skipUnless(shutil.which("systemd-analyze"), "systemd-analyze not installed")
    def test_units_pass_systemd_analyze_verify(self):
        tmp = tempfile.mkdtemp()
        try:
            paths = []
            for name in ("surfinspectd.service", "cell-agent.service"):
                with open(os.path.join(SRC, "deploy", "systemd", name)) as f:
                    text = f.read().replace("/usr/local/bin/", os.path.join(BIN, ""))
                paths.append(os.path.join(tmp, name))
                with open(paths[-1], "w") as f:
                    f.write(text)
            r = subprocess.run(["systemd-analyze", "verify", *paths], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            # Unknown keys are only warnings: catch them too.
            self.assertNotRegex(r.stderr, "Unknown|ignoring|Invalid|Failed")
        finally:
            shutil.rmtree(tmp)


if __name__ == "__main__":
    SRC = os.path.abspath(sys.argv[1])
    BIN = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)
