# Installs the diff_rigid_body Python client library (src/diff_rigid_body) and the
# example optimisers that use it (examples/diff_rigid_body_examples) through
# catkin_python_setup(); catkin merges the client with the generated
# diff_rigid_body.msg and diff_rigid_body.srv packages. Not meant to be run directly.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=['diff_rigid_body', 'diff_rigid_body_examples'],
    package_dir={'diff_rigid_body': 'src/diff_rigid_body',
                 'diff_rigid_body_examples': 'examples/diff_rigid_body_examples'},
))
