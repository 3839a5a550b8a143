"""JUnit XML (GitLab `artifacts:reports:junit`, Jenkins): a test suite per model.

Each model is one test suite; each finding at a failing severity is a failed test case
named after its rule and location; an input error is an errored test case. A clean model
is one passing test case, so the report shows that it was checked at all.
"""

from __future__ import annotations

from xml.etree import ElementTree as ET

from reedtool.report import ModelResult, display_path


def format_junit(results: list[ModelResult], failing: frozenset[str] = frozenset({"error"})) -> str:
    root = ET.Element("testsuites", name="reedtool validate")
    total_tests = total_failures = total_errors = 0
    for result in results:
        suite = ET.SubElement(root, "testsuite", name=result.name)
        tests = failures = errors = 0
        if result.error is not None:
            tests, errors = 1, 1
            case = ET.SubElement(suite, "testcase", classname=result.name, name="load model")
            ET.SubElement(case, "error", message=result.error, type="input-error").text = (
                f"{display_path(result.error_file) or result.name}"
                f"{':' + str(result.error_line) if result.error_line else ''}: {result.error}")
        elif result.skipped is not None:
            tests = 1
            case = ET.SubElement(suite, "testcase", classname=result.name, name="validate")
            ET.SubElement(case, "skipped", message=result.skipped)
        elif not result.findings:
            tests = 1
            ET.SubElement(suite, "testcase", classname=result.name, name="validate")
        for finding in result.findings:
            tests += 1
            where = display_path(finding.file) or result.name
            if finding.line:
                where += f":{finding.line}"
            case = ET.SubElement(suite, "testcase", classname=result.name,
                                 name=f"{finding.code} {finding.slug} {where}",
                                 file=display_path(finding.file) or result.name)
            if finding.line:
                case.set("line", str(finding.line))
            subject = f"[{finding.subject}] " if finding.subject else ""
            text = f"{where}: {finding.severity} {finding.code} {subject}{finding.message}"
            if finding.hint:
                text += f"\nhint: {finding.hint}"
            if finding.severity in failing:
                failures += 1
                ET.SubElement(case, "failure", message=f"{subject}{finding.message}",
                              type=finding.code).text = text
            else:
                # Below the failing severity: visible, but the test case passes.
                ET.SubElement(case, "system-out").text = text
        suite.set("tests", str(tests))
        suite.set("failures", str(failures))
        suite.set("errors", str(errors))
        total_tests, total_failures, total_errors = (total_tests + tests,
                                                     total_failures + failures,
                                                     total_errors + errors)
    root.set("tests", str(total_tests))
    root.set("failures", str(total_failures))
    root.set("errors", str(total_errors))
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") \
        + "\n"
