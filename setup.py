# Installs the diff_rigid_body Python client library (src/diff_rigid_body) through
# catkin_python_setup(); catkin merges it with the generated diff_rigid_body.msg
# and diff_rigid_body.srv packages. Not meant to be run directly.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=['diff_rigid_body'],
    package_dir={'': 'src'},
))
