#!/usr/bin/python3
"""Runs the `rosservice call` examples of README.md against the running node.

Every ```bash block of README.md that contains `rosservice call` is taken
(only those of the section under the heading ~section, e.g. "## Robots
(articulated bodies)", when that parameter is set: each section's examples
need their own scene); its commands run in order, through bash, as a reader
would paste them.
Comment lines right after a command ("# key: value") are the output the
README promises: each such key must be printed with that value. A command
without them must print `success: True`.
"""
import os
import re
import subprocess
import sys
import unittest

import rospy
import rospkg
import rostest

PKG = 'diff_rigid_body'


def readme_examples(readme_text):
    """[(command, [(key, value), ...])] of the bash blocks with `rosservice call`."""
    examples = []
    for block in re.findall(r'```bash\n(.*?)```', readme_text, re.S):
        if 'rosservice call' not in block:
            continue
        lines = block.splitlines()
        i = 0
        while i < len(lines):
            line = lines[i].rstrip()
            i += 1
            if not line.strip() or line.lstrip().startswith('#'):
                continue
            while line.endswith('\\') and i < len(lines):  # continued command
                line = line[:-1] + ' ' + lines[i].strip()
                i += 1
            expected = []
            while i < len(lines) and re.match(r'\s*#\s*\w+:', lines[i]):
                key, value = re.match(r'\s*#\s*(\w+):\s*(.*)$', lines[i]).groups()
                expected.append((key, value.strip()))
                i += 1
            examples.append((line.strip(), expected))
    return examples


def markdown_section(text, heading):
    """The lines from the line ``heading`` to the next heading of the same or a higher level
    (lines in ``` code blocks are never headings)."""
    level = len(heading) - len(heading.lstrip('#'))
    lines, start, in_code = text.splitlines(), None, False
    for i, line in enumerate(lines):
        if line.startswith('```'):
            in_code = not in_code
            continue
        if in_code or not line.startswith('#'):
            continue
        if start is None and line.strip() == heading:
            start = i
        elif start is not None and len(line) - len(line.lstrip('#')) <= level:
            return '\n'.join(lines[start:i]) + '\n'
    if start is None:
        raise ValueError('README.md has no heading %r' % heading)
    return '\n'.join(lines[start:]) + '\n'


def unquote(text):
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] and text[0] in '"\'':
        return text[1:-1]
    return text


class ReadmeExamples(unittest.TestCase):

    def test_rosservice_examples_work(self):
        readme = os.path.join(rospkg.RosPack().get_path(PKG), 'README.md')
        with open(readme) as f:
            text = f.read()
        section = rospy.get_param('~section', '')
        examples = readme_examples(markdown_section(text, section) if section else text)
        service_calls = [command for command, _ in examples if command.startswith('rosservice call')]
        self.assertTrue(service_calls, 'README.md has no ```bash block with `rosservice call`%s'
                        % (' in the section %r' % section if section else ''))
        # The node loads its meshes before it serves: wait, as a reader would.
        for service in sorted({command.split()[2] for command in service_calls}):
            rospy.wait_for_service(service, timeout=60.0)
        for command, expected in examples:
            run = subprocess.run(['bash', '-c', command], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 universal_newlines=True, timeout=60)
            output = run.stdout
            shown = output if len(output) <= 2000 else output[:2000] + '...\n'
            sys.stdout.write('$ %s\n%s\n' % (command, shown))
            self.assertEqual(run.returncode, 0, '`%s` exited with %d:\n%s' % (command, run.returncode, output))
            if not command.startswith('rosservice call'):
                continue
            printed = {}
            for line in output.splitlines():
                match = re.match(r'^(\w+): (.*)$', line)
                if match and match.group(1) not in printed:
                    printed[match.group(1)] = match.group(2)
            if not expected:
                expected = [('success', 'True')]
            for key, value in expected:
                self.assertIn(key, printed, '`%s` did not print %s:\n%s' % (command, key, output))
                self.assertEqual(unquote(printed[key]), unquote(value),
                                 '`%s`: README says %s: %s\n%s' % (command, key, value, output))


if __name__ == '__main__':
    rospy.init_node('readme_examples')
    rostest.rosrun(PKG, 'readme_examples', ReadmeExamples)
