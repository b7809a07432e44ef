#!/usr/bin/env python3
"""Writes a one-test JUnit XML file for a stage that is not a gtest/rostest run
(fuzzing, the sanitizer build), so that catkin_test_results and
summarize_test_results.py count it.

  junit_result.py OUT.xml SUITE CASE --seconds S [--failure MESSAGE]
                  [--log FILE] [--property NAME=VALUE ...]

With --failure the test case fails with MESSAGE and the last 200 lines of
--log as details; otherwise it passes and the log tail goes to system-out.
"""
import argparse
import pathlib
import xml.etree.ElementTree as ET


def tail(path, lines=200):
    if not path:
        return ''
    try:
        text = pathlib.Path(path).read_text(errors='replace')
    except OSError as error:
        return 'cannot read %s: %s' % (path, error)
    # XML 1.0 cannot carry most control characters.
    text = ''.join(c if c in '\n\t' or ord(c) >= 32 else '?' for c in text)
    return '\n'.join(text.splitlines()[-lines:])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('out')
    parser.add_argument('suite')
    parser.add_argument('case')
    parser.add_argument('--seconds', type=float, default=0.0)
    parser.add_argument('--failure')
    parser.add_argument('--log')
    parser.add_argument('--property', action='append', default=[])
    args = parser.parse_args()

    failed = args.failure is not None
    suite = ET.Element('testsuite', name=args.suite, tests='1', failures='1' if failed else '0', errors='0',
                       skipped='0', time='%.3f' % args.seconds)
    if args.property:
        properties = ET.SubElement(suite, 'properties')
        for item in args.property:
            name, _, value = item.partition('=')
            ET.SubElement(properties, 'property', name=name, value=value)
    case = ET.SubElement(suite, 'testcase', classname=args.suite, name=args.case, status='run',
                         time='%.3f' % args.seconds)
    if failed:
        failure = ET.SubElement(case, 'failure', message=args.failure, type='')
        failure.text = tail(args.log)
    else:
        ET.SubElement(case, 'system-out').text = tail(args.log, 40)
    pathlib.Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(suite).write(args.out, encoding='utf-8', xml_declaration=True)


if __name__ == '__main__':
    main()
