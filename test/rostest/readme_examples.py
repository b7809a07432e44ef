#!/usr/bin/python3
"""Runs the examples of README.md as written against the running nodes.

~examples selects what this run checks (each in its own test of readme_examples.test):

- "rosservice" (default): the `rosservice call` examples, below.
- "python": every ```python block marked `<!-- test: readme_examples.py: python -->` runs, each in
  a fresh namespace (the clients' and the pool's; /rigid_body_server, /pool1 and /pool2 serve the
  default scene).
- "cpp_package": the blocks marked `package.xml`, `CMakeLists.txt` and `src/drb_example.cpp`
  become a catkin package in a temporary workspace; every ```cpp block marked `snippet` is pasted
  into its main (its #include lines at the top, its statements in a block of their own, in the
  place of the skeleton's comment line); `catkin_make` builds it and the program must exit 0.

Every ```bash block of README.md that contains `rosservice call` is taken
(only those of the section under the heading ~section, e.g. "## Robots
(articulated bodies)", when that parameter is set: each section's examples
need their own scene); its commands run in order, through bash, as a reader
would paste them.
Comment lines right after a command ("# key: value") are the output the
README promises: each such key must be printed with that value. A command
without them must print `success: True`. After a command that is not a
`rosservice call`, "# prints: TEXT" says that its output contains TEXT.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
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


def marked_blocks(readme_text):
    """[(label, language, code)] of the fenced blocks right after `<!-- test: readme_examples.py: LABEL -->`."""
    pattern = r'<!-- test: readme_examples\.py: ([^ ]+) -->\n```(\w+)\n(.*?)```'
    return re.findall(pattern, readme_text, re.S)


def read_readme():
    with open(os.path.join(rospkg.RosPack().get_path(PKG), 'README.md')) as f:
        return f.read()


def paste_snippets(main, snippets):
    """`main` with each snippet's #include lines added after its own, and its other lines, in a block
    of their own, in the place of main's comment line inside main()."""
    includes, blocks = [], []
    for snippet in snippets:
        lines = snippet.splitlines()
        includes += [line for line in lines if line.startswith('#include') and line not in main]
        body = [line for line in lines if not line.startswith('#include')]
        blocks.append('  {\n' + '\n'.join('    ' + line for line in body) + '\n  }')
    marker = re.search(r'^  // .*\n', main, re.M)
    if marker is None:
        raise ValueError('src/drb_example.cpp of README.md has no comment line in main() for the calls')
    main = main[:marker.start()] + '\n'.join(blocks) + '\n' + main[marker.end():]
    return '\n'.join(includes) + ('\n' if includes else '') + main


class ReadmePythonExamples(unittest.TestCase):

    def test_marked_python_blocks_run(self):
        blocks = [code for label, language, code in marked_blocks(read_readme()) if label == 'python']
        self.assertGreaterEqual(len(blocks), 2, 'README.md: the client and pool Python blocks are not marked')
        for service in ('/rigid_body_server', '/pool1/rigid_body_server', '/pool2/rigid_body_server'):
            rospy.wait_for_service(service + '/get_bodies', timeout=60.0)
        for i, code in enumerate(blocks):
            sys.stdout.write('--- README.md Python block %d ---\n%s\n' % (i, code))
            exec(compile(code, 'README.md (Python block %d)' % i, 'exec'), {'__name__': 'readme_block'})


class ReadmeCppPackage(unittest.TestCase):

    def test_package_builds_and_runs_the_snippets(self):
        blocks = marked_blocks(read_readme())
        files = dict((label, code) for label, _, code in blocks
                     if label in ('package.xml', 'CMakeLists.txt', 'src/drb_example.cpp'))
        self.assertEqual(len(files), 3, 'README.md: the package files are not all marked: %s' % sorted(files))
        snippets = [code for label, language, code in blocks if label == 'snippet' and language == 'cpp']
        self.assertGreaterEqual(len(snippets), 2, 'README.md: the client and pool C++ snippets are not marked')
        files['src/drb_example.cpp'] = paste_snippets(files['src/drb_example.cpp'], snippets)
        workspace = tempfile.mkdtemp(prefix='drb_readme_ws_')
        self.addCleanup(shutil.rmtree, workspace, True)
        package = os.path.join(workspace, 'src', 'drb_example')
        for name, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(package, name)), exist_ok=True)
            with open(os.path.join(package, name), 'w') as f:
                f.write(text)
        sys.stdout.write('--- src/drb_example.cpp as built ---\n%s\n' % files['src/drb_example.cpp'])
        environment = dict(os.environ, PATH='/usr/bin:/bin:' + os.environ.get('PATH', ''), PWD=workspace)
        build = subprocess.run(['catkin_make', '-C', workspace, '-j2'], cwd=workspace, env=environment,
                               stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertEqual(build.returncode, 0, 'catkin_make of the README package failed:\n%s' % build.stdout[-6000:])
        for service in ('/rigid_body_server', '/pool1/rigid_body_server', '/pool2/rigid_body_server'):
            rospy.wait_for_service(service + '/get_bodies', timeout=60.0)
        run = subprocess.run([os.path.join(workspace, 'devel', 'lib', 'drb_example', 'drb_example')],
                             env=environment, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             universal_newlines=True, timeout=120)
        sys.stdout.write('--- drb_example ---\n%s\n' % run.stdout)
        self.assertEqual(run.returncode, 0, 'drb_example exited with %d:\n%s' % (run.returncode, run.stdout))


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
                for key, value in expected:  # "# prints: TEXT": the output holds TEXT
                    self.assertEqual(key, 'prints', '`%s`: only "# prints: ..." may follow it' % command)
                    self.assertIn(value, output, '`%s` did not print %r:\n%s' % (command, value, output))
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
    CASES = {'rosservice': ReadmeExamples, 'python': ReadmePythonExamples, 'cpp_package': ReadmeCppPackage}
    rostest.rosrun(PKG, 'readme_examples', CASES[rospy.get_param('~examples', 'rosservice')])
