#!/usr/bin/python3
"""Validate package.xml with ROS's own parser (catkin_pkg): format 3, build type
cmake, GPL-3.0-or-later, and the rosdep keys of the real dependencies."""
import sys

from catkin_pkg.package import parse_package

package = parse_package(sys.argv[1])
package.validate()
assert package.package_format == 3, package.package_format
assert package.name == "pcl_cocone_boundary", package.name
assert package.licenses == ["GPL-3.0-or-later"], package.licenses
build_type = [e.content for e in package.exports if e.tagname == "build_type"]
assert build_type == ["cmake"], build_type
depends = {d.name for d in package.build_depends}
for key in ("libpcl-all-dev", "cgal", "eigen", "libflann-dev"):
    assert key in depends, key
assert "gtest" in {d.name for d in package.test_depends}
print("package.xml: format 3, %s %s, %d build dependencies" %
      (package.name, package.version, len(depends)))
