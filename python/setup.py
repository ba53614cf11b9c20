"""The tase package: cffi API mode over the library's headers and sources
(python/tase/_build.py). The version is the C library's
(include/tase/version.h)."""

import os
import re

from setuptools import setup

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.environ.get("TASE_SOURCE_DIR") or os.path.dirname(HERE)


def version():
    with open(os.path.join(ROOT, "include", "tase", "version.h")) as f:
        text = f.read()
    parts = [
        re.search(r"^#define TASE_VERSION_%s (\d+)$" % k, text, re.M).group(1)
        for k in ("MAJOR", "MINOR", "PATCH")
    ]
    return ".".join(parts)


setup(
    name="tase",
    version=version(),
    description="The Cloud Cap TASE gimbal protocol over the tase C library",
    license="See LICENSE",
    packages=["tase"],
    python_requires=">=3.9",
    install_requires=["cffi>=1.15"],
    extras_require={"serial": ["pyserial"], "can": ["python-can"], "plot": ["matplotlib"]},
    cffi_modules=["tase/_build.py:ffibuilder"],
    zip_safe=False,
)
