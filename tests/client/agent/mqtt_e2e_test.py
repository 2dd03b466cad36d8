#!/usr/bin/env python3
"""cell-agent's MQTT events against a real mosquitto broker on loopback,
with a real surfinspectd and simulated parts: one started and at least one
result per part matching report.json; the retained status online, then
offline through the Last Will after kill -9; a broker stopped during a part
and restarted 5 s later; refused credentials; TLS with an openssl-made CA
and client certificate; results never acknowledged re-published at start;
bad settings refused. Standard library only, plus mosquitto_sub.

usage: mqtt_e2e_test.py BIN_DIR [unittest args]
"""
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

BIN = None
KEEPALIVE = 5  # s; the broker fires the Will after 1.5 x this without traffic


DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "docs", "integration.md")


def doc_samples():
    """docs/integration.md's ```LANG sample=NAME blocks, by name."""
    with open(DOC) as f:
        return {m.group(2): m.group(3) for m in re.finditer(r"```(\w+) sample=([\w-]+)\n(.*?)```", f.read(), re.S)}


def json_type(v):
    return "number" if isinstance(v, (int, float)) and not isinstance(v, bool) else type(v).__name__


def assert_like_sample(test, sample, real, where):
    """Every key of the real payload is in the sample, with the same JSON type
    (null stands for a number that may be missing); nested objects too."""
    test.assertEqual(sorted(real), sorted(sample), f"{where}: keys")
    for key, value in real.items():
        s = sample[key]
        if value is None or s is None:
            continue
        test.assertEqual(json_type(s), json_type(value), f"{where}.{key}")
        if isinstance(value, dict):
            assert_like_sample(test, s, value, f"{where}.{key}")
        if isinstance(value, list) and value and s and isinstance(value[0], dict):
            assert_like_sample(test, s[0], value[0], f"{where}.{key}[0]")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_port(port, timeout=10):
    deadline = time.time() + timeout
    while time.time() < deadline:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.05)
    raise AssertionError(f"nothing listens on {port}")



def part_folders(results):
    """The part folders in RESULTS/ (the results store's results.db sits there too)."""
    return sorted(e for e in os.listdir(results) if os.path.isdir(os.path.join(results, e)))

class Broker:
    """mosquitto from a config file written here; persistence in DIR/data."""

    def __init__(self, dir, port=None, persistence=False, passwords=None, tls=None):
        self.dir, self.port = dir, port or free_port()
        lines = [f"listener {self.port} 127.0.0.1", "user root"]
        if passwords:
            pw = os.path.join(dir, "passwords")
            open(pw, "w").close()
            for user, password in passwords.items():
                subprocess.run(["mosquitto_passwd", "-b", pw, user, password], check=True)
            lines += ["allow_anonymous false", f"password_file {pw}"]
        else:
            lines.append("allow_anonymous true")
        if tls:
            lines += [f"cafile {tls['ca']}", f"certfile {tls['cert']}", f"keyfile {tls['key']}",
                      "require_certificate true"]
        if persistence:
            os.makedirs(os.path.join(dir, "data"), exist_ok=True)
            lines += ["persistence true", f"persistence_location {os.path.join(dir, 'data')}/"]
        else:
            lines.append("persistence false")
        self.conf = os.path.join(dir, "mosquitto.conf")
        with open(self.conf, "w") as f:
            f.write("\n".join(lines) + "\n")
        self.proc = None

    def start(self):
        self.log = open(os.path.join(self.dir, "mosquitto.log"), "a")
        self.proc = subprocess.Popen(["mosquitto", "-c", self.conf], stdout=self.log, stderr=self.log)
        wait_port(self.port)
        return self

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)  # saves the persistence database
            self.proc.wait(timeout=20)
            self.log.close()


class Subscriber:
    """mosquitto_sub with a persistent session (-c), QoS 1, topic + payload
    per line; it reconnects by itself when the broker comes back."""

    def __init__(self, broker, path, tls=None, client_id="surfinspect-test-sub"):
        self.path = path
        cmd = ["mosquitto_sub", "-h", "127.0.0.1", "-p", str(broker.port), "-q", "1", "-c", "-i", client_id,
               "-v", "-t", "surfinspect/#", *client_options(tls)]
        self.out = open(path, "w")
        self.proc = subprocess.Popen(cmd, stdout=self.out, stderr=subprocess.STDOUT)

    def messages(self):
        with open(self.path) as f:
            rows = [l.rstrip("\n").split(" ", 1) for l in f if " {" in l]
        return [(topic, json.loads(payload)) for topic, payload in rows]

    def wait_for(self, pred, timeout=120, what="message"):
        deadline = time.time() + timeout
        while time.time() < deadline:
            hits = [m for m in self.messages() if pred(*m)]
            if hits:
                return hits
            time.sleep(0.1)
        raise AssertionError(f"no {what} within {timeout} s; got {self.messages()}")

    def stop(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        self.out.close()


def client_options(tls):
    """mosquitto_sub's TLS and login options (the TLS broker also wants a password)."""
    if not tls:
        return []
    return ["--cafile", tls["ca"], "--cert", tls["client_cert"], "--key", tls["client_key"],
            "-u", "sub", "-P", "sub-pw"]


def retained_status(broker, tls=None):
    cmd = ["mosquitto_sub", "-h", "127.0.0.1", "-p", str(broker.port), "-t", "surfinspect/v1/cell/status",
           "-C", "1", "-W", "2", *client_options(tls)]
    out = subprocess.run(cmd, capture_output=True, text=True).stdout.strip()
    return json.loads(out)["state"] if out else None


def make_tls(dir):
    """A CA, a server certificate for 127.0.0.1 and a client certificate."""
    def run(*args):
        subprocess.run(["openssl", *args], check=True, capture_output=True, cwd=dir)
    ec = ["-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes"]
    run("req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.pem", "-days", "2", "-subj", "/CN=surfinspect test CA")
    with open(os.path.join(dir, "san.ext"), "w") as f:
        f.write("subjectAltName=IP:127.0.0.1\n")
    for name, cn in (("server", "127.0.0.1"), ("client", "cell-agent")):
        run("req", *ec, "-keyout", f"{name}.key", "-out", f"{name}.csr", "-subj", f"/CN={cn}")
        run("x509", "-req", "-in", f"{name}.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial",
            "-out", f"{name}.pem", "-days", "2", *(["-extfile", "san.ext"] if name == "server" else []))
    p = lambda n: os.path.join(dir, n)
    return {"ca": p("ca.pem"), "cert": p("server.pem"), "key": p("server.key"),
            "client_cert": p("client.pem"), "client_key": p("client.key")}


class MqttTests(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="mqtt-e2e-")
        cell = os.path.join(cls.root, "cell")
        subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", cell, "--parts", "0"],
                       check=True, stdout=subprocess.DEVNULL)
        cls.server_port = free_port()
        cls.server = subprocess.Popen(
            [os.path.join(BIN, "surfinspectd"), "--listen", f"127.0.0.1:{cls.server_port}", "--threads", "1"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        assert "listening on" in cls.server.stdout.readline()
        cls.server.stdout.close()
        subprocess.run([os.path.join(BIN, "cell-agent"), "calibrate", "--cell", os.path.join(cell, "cell.json"),
                        "--server", f"127.0.0.1:{cls.server_port}"], check=True, capture_output=True)
        cls.cell = cell

    @classmethod
    def tearDownClass(cls):
        cls.server.kill()
        cls.server.wait()
        shutil.rmtree(cls.root, ignore_errors=True)

    def setUp(self):
        self.dir = tempfile.mkdtemp(dir=self.root)
        shutil.copytree(self.cell, os.path.join(self.dir, "cell"))
        self.stoppers = []

    def tearDown(self):
        for stop in reversed(self.stoppers):
            stop()

    def broker(self, **kw):
        b = Broker(self.dir, **kw).start()
        self.stoppers.append(b.stop)
        return b

    def subscriber(self, broker, **kw):
        s = Subscriber(broker, os.path.join(self.dir, f"sub-{len(self.stoppers)}.txt"), **kw)
        self.stoppers.append(s.stop)
        return s

    def agent(self, *extra, wait=True):
        cmd = [os.path.join(BIN, "cell-agent"), "run", "--cell", "cell/cell.json",
               "--server", f"127.0.0.1:{self.server_port}", "--inbox", "inbox", "--results", "results",
               "--backoff", "0.2", "--backoff-max", "1", "--poll", "0.2",
               "--mqtt-keepalive", str(KEEPALIVE), *extra]
        proc = subprocess.Popen(cmd, cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if not wait:
            self.stoppers.append(lambda: (proc.poll() is None and proc.kill(), proc.communicate()))
            return proc
        out, err = proc.communicate(timeout=400)
        return proc.returncode, out, err

    def report(self, part):
        with open(os.path.join(self.dir, "results", part, "report.json")) as f:
            return json.load(f)

    def assert_result_matches_report(self, part, payload):
        report = self.report(part)
        self.assertEqual(payload["schema"], "surfinspect.event.result/1")
        self.assertEqual(payload["part_id"], part)
        self.assertEqual(payload["cell"], "cell")
        self.assertEqual(payload["verdict"], report["verdict"])
        self.assertEqual(payload["characteristics"], len(report["characteristics"]))
        self.assertEqual([f["name"] for f in payload["failed"]],
                         [c["name"] for c in report["characteristics"] if c["verdict"] != "pass"])
        self.assertEqual(payload["defects"], len(report["defects"]))
        self.assertEqual(payload["min_mm"], report["statistics"]["min_mm"])
        self.assertEqual(payload["max_mm"], report["statistics"]["max_mm"])
        for key in ("report", "qif", "errormap_ply", "errormap_png"):
            self.assertTrue(os.path.isfile(payload["files"][key]), key)
        self.assertNotIn("deviations_csv", payload["files"])  # only files that exist; CSV off by default
        self.assertEqual(os.path.realpath(payload["files"]["report"]),
                         os.path.realpath(os.path.join(self.dir, "results", part, "report.json")))

    def test_three_parts_one_started_and_results_matching_the_reports(self):
        broker = self.broker()
        sub = self.subscriber(broker)
        time.sleep(0.3)
        code, out, err = self.agent("--mqtt", f"tcp://127.0.0.1:{broker.port}", "--simulate", "3", "--once")
        self.assertEqual(code, 0, err)
        parts = part_folders(os.path.join(self.dir, "results"))
        self.assertEqual(len(parts), 3)
        sub.wait_for(lambda t, p: t == "surfinspect/v1/cell/status" and p["state"] == "offline",
                     what="offline status at the clean stop")
        msgs = sub.messages()
        for part in parts:
            started = [p for t, p in msgs if t == f"surfinspect/v1/cell/{part}/started"]
            results = [p for t, p in msgs if t == f"surfinspect/v1/cell/{part}/result"]
            self.assertEqual(len(started), 1, part)
            self.assertEqual(started[0]["part_id"], part)
            self.assertGreaterEqual(len(results), 1, part)
            self.assertEqual(len({r["idempotency_key"] for r in results}), 1)
            for r in results:
                self.assert_result_matches_report(part, r)
            self.assertTrue(os.path.exists(os.path.join(self.dir, "results", part, ".mqtt-delivered")))
        states = [p["state"] for t, p in msgs if t.endswith("/status")]
        self.assertEqual((states[0], states[-1]), ("online", "offline"))
        self.assertEqual(retained_status(broker), "offline")
        # The samples in docs/integration.md are true of this output.
        samples = doc_samples()
        failing = [p for t, p in msgs if t.endswith("/result") and p["failed"]]
        self.assertTrue(failing, "no failing part to check the sample's failed[] against")
        assert_like_sample(self, json.loads(samples["mqtt-result"]), failing[0], "result")
        assert_like_sample(self, json.loads(samples["mqtt-started"]),
                           [p for t, p in msgs if t.endswith("/started")][0], "started")
        assert_like_sample(self, json.loads(samples["mqtt-status"]),
                           [p for t, p in msgs if t.endswith("/status")][-1], "status")
        documented = {l.split()[0].split("/", 2)[2] for l in samples["folder"].splitlines()
                      if l.startswith("RESULTS/<part>/")}
        for part in parts:
            self.assertEqual(sorted(os.listdir(os.path.join(self.dir, "results", part))), sorted(documented))

    def test_status_online_then_offline_by_the_last_will_after_kill_9(self):
        broker = self.broker()
        agent = self.agent("--mqtt", f"tcp://127.0.0.1:{broker.port}", wait=False)
        deadline = time.time() + 30
        while retained_status(broker) != "online":
            self.assertLess(time.time(), deadline, "never online")
            time.sleep(0.2)
        agent.kill()  # SIGKILL: no clean disconnect, so only the Will can say offline
        killed = time.time()
        while retained_status(broker) != "offline":
            self.assertLess(time.time() - killed, 1.5 * KEEPALIVE + 3, "the Last Will did not fire")
            time.sleep(0.2)
        print(f"offline {time.time() - killed:.1f} s after kill -9 (keep-alive {KEEPALIVE} s)", file=sys.stderr)

    def test_an_unusable_calibration_is_the_retained_status(self):
        broker = self.broker()
        path = os.path.join(self.dir, "cell", "cell.json")
        with open(path) as f:
            cell = json.load(f)
        del cell["viewpoints"][1]["world_from_sensor"]
        with open(path, "w") as f:
            json.dump(cell, f)
        code, out, err = self.agent("--mqtt", f"tcp://127.0.0.1:{broker.port}", "--simulate", "1", "--once")
        self.assertEqual(code, 2, err)
        self.assertIn("is not calibrated", err)
        self.assertEqual(retained_status(broker), "calibration_expired")

    def test_broker_stopped_during_a_part_and_restarted_5_s_later(self):
        broker = self.broker(persistence=True)
        sub = self.subscriber(broker)
        agent = self.agent("--mqtt", f"tcp://127.0.0.1:{broker.port}", "--simulate", "1", wait=False)
        started = sub.wait_for(lambda t, p: t.endswith("/started"), what="started")[0][1]
        part = started["part_id"]
        broker.stop()
        self.assertFalse(os.path.exists(os.path.join(self.dir, "results", part, "report.json")),
                         "the part ended before the broker stopped; nothing was tested")
        time.sleep(5)
        broker.start()
        hits = sub.wait_for(lambda t, p: t == f"surfinspect/v1/cell/{part}/result", timeout=60,
                            what="result after the broker came back")
        self.assert_result_matches_report(part, hits[0][1])
        agent.send_signal(signal.SIGTERM)
        agent.communicate(timeout=60)

    def test_refused_credentials_are_named_and_results_still_written(self):
        broker = self.broker(passwords={"cell": "right"})
        with open(os.path.join(self.dir, "pw.txt"), "w") as f:
            f.write("wrong\n")
        code, out, err = self.agent("--mqtt", f"tcp://127.0.0.1:{broker.port}", "--mqtt-username", "cell",
                                    "--mqtt-password-file", "pw.txt", "--simulate", "1", "--once")
        self.assertEqual(code, 0, err)
        self.assertIn("refused the connection", err)
        self.assertIn("not authorised", err)
        self.assertIn("check the username and password file", err)
        parts = part_folders(os.path.join(self.dir, "results"))
        self.assertEqual(len(parts), 1)
        self.assertTrue(os.path.exists(os.path.join(self.dir, "results", parts[0], "report.json")))
        self.assertFalse(os.path.exists(os.path.join(self.dir, "results", parts[0], ".mqtt-delivered")))

    def test_tls_with_an_openssl_ca_and_undelivered_results_republished_at_start(self):
        tls = make_tls(self.dir)
        broker = self.broker(tls=tls, passwords={"cell": "s3cret", "sub": "sub-pw"})
        with open(os.path.join(self.dir, "pw.txt"), "w") as f:
            f.write("s3cret\n")
        # A result on disk whose event was never acknowledged (MQTT was off).
        part_dir = os.path.join(self.dir, "results", "old-part")
        os.makedirs(part_dir)
        report = {"schema": "surfinspect.report/2", "verdict": "pass", "characteristics": [],
                  "defects": [], "statistics": {"min_mm": -0.1, "max_mm": 0.1}}
        with open(os.path.join(part_dir, "report.json"), "w") as f:
            json.dump(report, f)
        sub = self.subscriber(broker, tls={**tls}, client_id="tls-sub")
        time.sleep(0.5)
        agent = self.agent("--mqtt", f"mqtts://127.0.0.1:{broker.port}", "--mqtt-ca", tls["ca"],
                           "--mqtt-cert", tls["client_cert"], "--mqtt-key", tls["client_key"],
                           "--mqtt-username", "cell", "--mqtt-password-file", "pw.txt", wait=False)
        hit = sub.wait_for(lambda t, p: t == "surfinspect/v1/cell/old-part/result", timeout=30,
                           what="re-published result over TLS")[0][1]
        self.assertEqual(hit["verdict"], "pass")
        self.assertEqual(retained_status(broker, tls), "online")
        deadline = time.time() + 10
        while not os.path.exists(os.path.join(part_dir, ".mqtt-delivered")):
            self.assertLess(time.time(), deadline, "no delivery mark")
            time.sleep(0.1)
        agent.send_signal(signal.SIGTERM)
        _, err = agent.communicate(timeout=60)
        self.assertIn("mqtt: connected to mqtts://", err)
        self.assertEqual(retained_status(broker, tls), "offline")

    def test_bad_settings_are_refused_and_an_unreachable_broker_never_blocks(self):
        cases = [
            (["--mqtt", "http://127.0.0.1:1883"], 'unknown scheme "http"'),
            (["--mqtt", "mqtts://127.0.0.1:8883", "--mqtt-ca", "no-such-ca.pem"], "CA file: no such file"),
            (["--mqtt", "tcp://127.0.0.1:1883", "--mqtt-topic-prefix", "plant/#"], "wildcard"),
            (["--mqtt", "tcp://127.0.0.1:1883", "--mqtt-topic-prefix", "plant/+/x"], "wildcard"),
        ]
        for args, message in cases:
            code, out, err = self.agent(*args, "--once")
            self.assertEqual(code, 2, args)
            self.assertIn(message, err, args)
        # cell.json's block is checked by the same validator.
        path = os.path.join(self.dir, "cell", "cell.json")
        with open(path) as f:
            cell = json.load(f)
        cell["mqtt"] = {"url": "tcp://127.0.0.1:1883", "topic_prefix": "a/#"}
        with open(path, "w") as f:
            json.dump(cell, f)
        code, out, err = self.agent("--once")
        self.assertEqual(code, 2)
        self.assertIn("wildcard", err)
        # Nothing listens on this port: an error at start-up, and the part is
        # still inspected and written.
        cell["mqtt"] = {"url": f"tcp://127.0.0.1:{free_port()}"}
        with open(path, "w") as f:
            json.dump(cell, f)
        t0 = time.time()
        code, out, err = self.agent("--simulate", "1", "--once")
        self.assertEqual(code, 0, err)
        self.assertIn("cannot reach the broker", err)
        parts = part_folders(os.path.join(self.dir, "results"))
        self.assertEqual(len(parts), 1)
        self.assertTrue(os.path.exists(os.path.join(self.dir, "results", parts[0], "report.json")))
        print(f"unreachable broker: 1 part in {time.time() - t0:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    BIN = os.path.abspath(sys.argv.pop(1))
    if shutil.which("mosquitto") is None or shutil.which("mosquitto_sub") is None:
        print("SKIPPED: mosquitto or mosquitto_sub not installed (./run deps installs them)", file=sys.stderr)
        sys.exit(0)
    unittest.main()
