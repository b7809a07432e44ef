#!/usr/bin/python3
"""Claims of README.md and of the scripts' headers that follow from the code or the platform
(doc_claims.test), so that they cannot go stale:

- "every Nth vertex" (the dp/dx arrows of jacobian_column, README.md and scripts/rviz_screenshot)
  is nodes/vertex_markers.py's default ~arrow_stride;
- the tf command the README gives is one a Debian user has: tf2_tools' echo.py (Debian's
  tf2-tools, installed by scripts/common.sh), found by rospack; tf_echo of the tf package, which
  Debian does not ship, is named only beside it. readme_examples.test runs that command as written.
"""
import os
import re
import unittest

import rospkg
import rostest

PKG = 'diff_rigid_body'
ORDINAL = {1: 'st', 2: 'nd', 3: 'rd'}


def read(*parts):
    with open(os.path.join(rospkg.RosPack().get_path(PKG), *parts)) as f:
        return f.read()


def ordinal(n):
    return '%d%s' % (n, 'th' if 10 <= n % 100 <= 20 else ORDINAL.get(n % 10, 'th'))


class DocClaims(unittest.TestCase):

    def test_every_nth_vertex_is_the_markers_arrow_stride(self):
        default = re.search(r"get_param\('~arrow_stride', (\d+)\)", read('nodes', 'vertex_markers.py'))
        self.assertIsNotNone(default, "vertex_markers.py: no rospy.get_param('~arrow_stride', N)")
        expected = 'every %s vertex' % ordinal(int(default.group(1)))
        for parts in (('README.md',), ('scripts', 'rviz_screenshot')):
            claims = re.findall(r'every \d+(?:st|nd|rd|th) vertex', read(*parts))
            self.assertTrue(claims, '%s says nothing of the arrows\' stride' % '/'.join(parts))
            for claim in claims:
                self.assertEqual(claim, expected, '%s: %r, but ~arrow_stride defaults to %s'
                                 % ('/'.join(parts), claim, default.group(1)))

    def test_the_readme_tf_tools_are_debians(self):
        readme = read('README.md')
        for sentence in re.split(r'(?<=[.!?])\s+', ' '.join(readme.split())):
            if 'tf_echo' in sentence:
                self.assertIn('tf2_tools', sentence, "README.md names tf_echo (package tf), which Debian's ROS does "
                              'not ship, without saying what to use instead: %r' % sentence)
        self.assertIn('rosrun tf2_tools echo.py', readme)
        self.assertIn('tf2-tools', readme, 'README.md: name the Debian package of echo.py')
        self.assertIn('tf2-tools', read('scripts', 'common.sh'), 'scripts/common.sh does not install tf2-tools')
        path = rospkg.RosPack().get_path('tf2_tools')
        self.assertTrue(any(os.path.isfile(os.path.join(folder, 'echo.py'))
                            for folder in (path, '/usr/lib/tf2_tools')), 'tf2_tools has no echo.py')

    def test_the_repository_cites_only_itself(self):
        """A user's clone holds the package alone: no file may cite design notes that are not in it
        (the contract is docs/interface.md, the derivations docs/derivation.md)."""
        root = rospkg.RosPack().get_path(PKG)
        outside = re.compile(r'\.\./shared|\b(?:math|style)\.md\b|appendix\.txt')
        for folder, folders, files in os.walk(root):
            folders[:] = [f for f in folders if not f.startswith('.') and f != 'third_party']
            for name in files:
                path = os.path.join(folder, name)
                try:
                    with open(path, encoding='utf-8') as f:
                        text = f.read()
                except (UnicodeDecodeError, OSError):
                    continue  # meshes, images
                found = outside.search(text)
                self.assertIsNone(found, '%s cites %r, which a clone does not have'
                                  % (os.path.relpath(path, root), found and found.group(0)))
                if 'interface.md' in text:
                    self.assertTrue(os.path.isfile(os.path.join(root, 'docs', 'interface.md')), path)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'doc_claims', DocClaims)
