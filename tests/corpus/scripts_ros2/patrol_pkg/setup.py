# Course pattern: an ament_python package's setup.py - console_scripts name the nodes.
import os
from glob import glob

from setuptools import find_packages, setup

package_name = "patrol_pkg"

setup(
    name=package_name,
    version="0.0.1",
    packages=find_packages(exclude=["test"]),
    data_files=[
        ("share/ament_index/resource_index/packages", ["resource/" + package_name]),
        ("share/" + package_name, ["package.xml"]),
        (os.path.join("share", package_name, "launch"), glob("launch/*.launch.py")),
        (os.path.join("share", package_name, "config"), glob("config/*.yaml")),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="student",
    maintainer_email="student@example.org",
    description="A TurtleBot3 patrol and an odometry logger",
    license="Apache-2.0",
    tests_require=["pytest"],
    entry_points={
        "console_scripts": [
            "patrol = patrol_pkg.patrol:main",
            "odom_logger = patrol_pkg.odom_logger:main",
        ],
    },
)
