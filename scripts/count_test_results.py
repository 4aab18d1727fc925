#!/usr/bin/env python3
"""Counts test cases in the JUnit XML files catkin writes (gtest, rostest, rosunit).

catkin_test_results counts the "tests" attribute of both <testsuites> and <testsuite>, so gtest
files are counted twice; this counts <testcase> elements. A file that does not parse (a test
binary that crashed mid-write) counts as one failure. Prints "passed failed skipped".
"""
import pathlib
import sys
import xml.etree.ElementTree as ElementTree


def count(results_dir):
    passed = failed = skipped = 0
    for path in sorted(pathlib.Path(results_dir).rglob("*.xml")):
        try:
            cases = ElementTree.parse(path).getroot().iter("testcase")
        except ElementTree.ParseError as error:
            print(f"unreadable result {path}: {error}", file=sys.stderr)
            failed += 1
            continue
        for case in cases:
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
                print(f"FAILED {path.name}: {case.get('classname')}.{case.get('name')}",
                      file=sys.stderr)
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
    return passed, failed, skipped


if __name__ == "__main__":
    print(*count(sys.argv[1]))
