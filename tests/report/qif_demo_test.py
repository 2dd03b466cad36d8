#!/usr/bin/env python3
"""Every result.qif of the demo (surfinspect demo-cell, calibrated on a real
surfinspectd, each part inspected with the cell's plan in-process and one
through the server, plus `surfinspect errormap --qif`) validates against the
QIF 3.0 XSD with xmllint, and reads back with each characteristic's value,
tolerance and status equal to report.json's.

The schemas are not the project's: they are taken from ../shared/qif-3.0
beside the checkout (SOURCE_DIR/../shared/qif-3.0); without them the schema
check is SKIPPED, loudly, and the read-back still runs.

usage: qif_demo_test.py BIN_DIR SOURCE_DIR
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

NS = {"q": "http://qifstandards.org/xsd/qif3"}


def expected_measurements(c, planes):
    """The QIF characteristics of one report characteristic: (kind, name, value, band).
    `planes`: the names of the report's sections (a section with its plane
    is a line profile)."""
    if c["type"] not in ("hole", "slot"):
        kind = "PointProfile" if c["type"] in ("point", "edge_point") else "SurfaceProfile"
        if c["type"] == "section" and c["name"] in planes:
            kind = "LineProfile"
        return [(kind, c["name"], None, None)]
    size = "width" if c["type"] == "slot" else "diameter"
    out = [(size.capitalize(), c["name"] + " " + size, c.get("measured_%s_mm" % size),
            c["tolerance_mm"])]
    if c["type"] == "slot":
        out.append(("Length", c["name"] + " length", c.get("measured_length_mm"),
                    c["length_tolerance_mm"]))
    out.append(("Position", c["name"] + " position", c.get("true_position_mm"),
                c["position_tolerance_mm"]))
    return out


def check_hole_part(m, definition, c, value, band):
    """A hole's diameter, width, length or position against the report's hole."""
    status = m.find("q:Status/q:CharacteristicStatusEnum", NS).text
    if c["verdict"] == "not_measured":
        assert status == "INDETERMINATE" and m.find("q:Value", NS) is None, c["name"]
        return status
    assert status == "PASS" or c["verdict"] == "fail", (c["name"], status)
    assert float(m.find("q:Value", NS).text) == value, (c["name"], value)
    if isinstance(band, dict):
        assert float(definition.find("q:Tolerance/q:MaxValue", NS).text) == band["upper"]
        assert float(definition.find("q:Tolerance/q:MinValue", NS).text) == band["lower"]
    else:
        assert float(definition.find("q:ToleranceValue", NS).text) == band, c["name"]
    return status


def check_against_report(qif_path, report):
    """The QIF's characteristics against the report's, in order (a hole gives
    a diameter and a position, a slot a width, a length and a position)."""
    root = ET.parse(qif_path).getroot()
    by_id = {e.get("id"): e for e in root.iter() if e.get("id")}
    status = root.find("q:Results/q:MeasurementResultsSet/q:MeasurementResults/q:InspectionStatus/"
                       "q:InspectionStatusEnum", NS).text
    assert status == report["verdict"].upper(), (qif_path, status)
    measurements = iter(root.find(".//q:CharacteristicMeasurements", NS))
    chars = report["characteristics"]
    assert chars, qif_path
    for c in chars:
        statuses = []
        for kind, name, value, band in expected_measurements(
                c, {s["name"] for s in report.get("sections", [])}):
            m = next(measurements)
            assert m.tag == "{%s}%sCharacteristicMeasurement" % (NS["q"], kind), (m.tag, name)
            item = by_id[m.find("q:CharacteristicItemId", NS).text]
            assert item.find("q:Name", NS).text == name
            definition = by_id[by_id[item.find("q:CharacteristicNominalId", NS).text]
                               .find("q:CharacteristicDefinitionId", NS).text]
            if band is not None:
                statuses.append(check_hole_part(m, definition, c, value, band))
                continue
            # QIF has no "not measured" characteristic status: INDETERMINATE.
            expected = "INDETERMINATE" if c["verdict"] == "not_measured" else c["verdict"].upper()
            assert m.find("q:Status/q:CharacteristicStatusEnum", NS).text == expected, name
            lower, upper = c["tolerance_mm"]["lower"], c["tolerance_mm"]["upper"]
            assert float(definition.find("q:ToleranceValue", NS).text) == upper - lower, name
            value = m.find("q:Value", NS)
            if not c["points"]:
                assert value is None, name
                continue
            expected = (c["value_mm"] if c["type"] in ("point", "edge_point")
                        else 2 * max(abs(c["min_mm"]), abs(c["max_mm"])))
            assert float(value.text) == expected, (name, value.text, expected)
            worst = (c["value_mm"], c["value_mm"]) if c["type"] == "edge_point" else (
                c["max_mm"], c["min_mm"])
            assert float(m.find("q:WorstPositiveDeviation", NS).text) == worst[0], name
            assert float(m.find("q:WorstNegativeDeviation", NS).text) == worst[1], name
        assert c["verdict"] != "fail" or not statuses or "FAIL" in statuses, c["name"]
    assert next(measurements, None) is None, "more QIF characteristics than the report's"
    uri = root.find(".//q:ExternalFileReference/q:URI", NS).text
    assert os.path.isfile(os.path.join(os.path.dirname(qif_path), uri)), uri
    return len(chars)


def element_paths(root):
    """Every element's path of tag names (namespace dropped) below the root."""
    paths = set()

    def walk(e, prefix):
        path = prefix + "/" + e.tag.split("}")[-1]
        paths.add(path)
        for child in e:
            walk(child, path)
    walk(root, "")
    return paths


def check_doc_sample(source, qif_path):
    """docs/integration.md's QIF sample: each of its element paths is in a real file."""
    with open(os.path.join(source, "docs", "integration.md")) as f:
        sample = re.search(r"```xml sample=qif\n(.*?)```", f.read(), re.S).group(1)
    missing = element_paths(ET.fromstring(sample)) - element_paths(ET.parse(qif_path).getroot())
    assert not missing, f"docs/integration.md's QIF sample has paths no real file has: {sorted(missing)}"


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    bin_dir, source = map(os.path.abspath, sys.argv[1:])
    xsd = os.path.join(source, "..", "shared", "qif-3.0", "QIFApplications", "QIFDocument.xsd")
    work = tempfile.mkdtemp(prefix="qif-demo-")
    si = os.path.join(bin_dir, "surfinspect")
    server = None
    try:
        os.chdir(work)
        subprocess.run([si, "demo-cell", "--out", "cell", "--parts", "2"], check=True, capture_output=True)
        server = subprocess.Popen([os.path.join(bin_dir, "surfinspectd"), "--listen", "127.0.0.1:0"],
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        target = server.stdout.readline().split("listening on ")[-1].strip()
        subprocess.run([os.path.join(bin_dir, "cell-agent"), "calibrate", "--cell", "cell/cell.json",
                        "--server", target], check=True, capture_output=True)
        runs = []
        for part in sorted(os.listdir("cell/scans")):
            out = f"inspect/{part}"
            subprocess.run([si, "inspect", "--cell", "cell/cell.json", "--scans", f"cell/scans/{part}",
                            "--out", out], check=True, capture_output=True)
            runs.append((f"{out}/result.qif", f"{out}/report.json"))
        subprocess.run([si, "inspect", "--cell", "cell/cell.json", "--scans", "cell/scans/part-001",
                        "--out", "remote", "--server", target], check=True, capture_output=True)
        runs.append(("remote/result.qif", "remote/report.json"))
        with open("cell/cell.json") as f:
            json.dump(json.load(f)["part"]["world_from_part"], open("wfp.json", "w"))
        os.makedirs("em")
        # The scan stays in the sensor frame: nothing matches, so every
        # characteristic is not measured (QIF: INDETERMINATE) and validates.
        subprocess.run([si, "errormap", "--cloud", "cell/scans/part-001/v3.pcd", "--mesh", "cell/part.stl",
                        "--world-from-part", "wfp.json", "--plan", "cell/plan.json", "--out", "em/e.ply",
                        "--report", "em/e.json", "--qif", "em/e.qif"], check=True, capture_output=True)
        with open("em/e.json") as f:
            assert json.load(f)["characteristics"][0]["verdict"] == "not_measured"
        runs.append(("em/e.qif", "em/e.json"))
        # Without a plan the whole surface is the one characteristic.
        subprocess.run([si, "errormap", "--cloud", "cell/scans/part-002/v1.pcd", "--mesh", "cell/part.stl",
                        "--world-from-part", "wfp.json", "--out", "em/s.ply", "--report", "em/s.json",
                        "--qif", "em/s.qif"], check=True, capture_output=True)
        runs.append(("em/s.qif", "em/s.json"))
        if os.path.exists(xsd):
            r = subprocess.run(["xmllint", "--noout", "--nonet", "--schema", xsd, *[q for q, _ in runs]],
                               capture_output=True, text=True)
            assert r.returncode == 0, r.stderr
            print(f"QIF 3.0 schema: {len(runs)} files validate ({r.stderr.count('validates')} reported)")
        else:
            print("=" * 72 + f"\nSKIPPED the QIF 3.0 schema check: no {os.path.normpath(xsd)}\n"
                  "(the schemas are not the project's; see docs/integration.md)\n" + "=" * 72)
        for qif, report in runs:
            with open(report) as f:
                n = check_against_report(qif, json.load(f))
            print(f"{qif}: {n} characteristics equal the report's")
        check_doc_sample(source, runs[0][0])
        print("docs/integration.md's QIF sample: every element path occurs in", runs[0][0])
    finally:
        if server:
            server.kill()
            server.wait()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
