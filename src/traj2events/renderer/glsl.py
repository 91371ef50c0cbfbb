"""GLSL sources and programs: the package's shaders (shaders/) with their includes expanded
and their defines set, compiled and linked into a program whose failure names its shader,
and uniforms set by their Python type."""

from __future__ import annotations

from collections.abc import Iterable
from importlib import resources

import numpy as np


def expand_includes(source: str) -> str:
    """GLSL `source` with each `#include "file"` line replaced by shaders/file. GLSL has no
    includes; this keeps the reflectance law in one file for every stage that evaluates it."""
    folder = resources.files("traj2events.renderer") / "shaders"
    lines = source.splitlines(keepends=True)
    return "".join(
        (folder / line.split('"')[1]).read_text() if line.startswith("#include ") else line for line in lines
    )


def shader_source(name: str) -> str:
    """shaders/`name`, includes expanded."""
    return expand_includes((resources.files("traj2events.renderer") / "shaders" / name).read_text())


def with_defines(source: str, defines: tuple[str, ...]) -> str:
    """GLSL `source` with a `#define` line for each of `defines` after its `#version` line."""
    version, rest = source.split("\n", 1)
    return "".join(f"{line}\n" for line in (version, *(f"#define {name}" for name in defines))) + rest


def compile_program(gl, stages: Iterable[tuple[int, str, str]]) -> int:
    """The program linked from `stages`, each (shader kind, its name for errors, its
    source); a RuntimeError with the compiler's log, naming the shader, if one fails."""
    program = gl.glCreateProgram()
    for kind, name, source in stages:
        shader = gl.glCreateShader(kind)
        gl.glShaderSource(shader, source)
        gl.glCompileShader(shader)
        if not gl.glGetShaderiv(shader, gl.GL_COMPILE_STATUS):
            raise RuntimeError(f"{name}: {gl.glGetShaderInfoLog(shader).decode()}")
        gl.glAttachShader(program, shader)
        gl.glDeleteShader(shader)  # freed with the program
    gl.glLinkProgram(program)
    if not gl.glGetProgramiv(program, gl.GL_LINK_STATUS):
        raise RuntimeError(f"shaders: {gl.glGetProgramInfoLog(program).decode()}")
    return program


def package_program(gl, stem: str, defines: tuple[str, ...] = ()) -> int:
    """The program of shaders/`stem`.vert and shaders/`stem`.frag, with `defines` set."""
    return compile_program(
        gl,
        (
            (kind, f"shaders/{name}", with_defines(shader_source(name), defines))
            for kind, name in ((gl.GL_VERTEX_SHADER, f"{stem}.vert"), (gl.GL_FRAGMENT_SHADER, f"{stem}.frag"))
        ),
    )


def set_uniform(gl, location: int, value) -> None:
    """Sets the current program's uniform at `location` by `value`'s type: an int, a
    float, a 4 x 4 matrix (row-major, as numpy holds it) or a 3-vector (in float32)."""
    if isinstance(value, int):
        gl.glUniform1i(location, value)
    elif isinstance(value, float):
        gl.glUniform1f(location, value)
    elif np.shape(value) == (4, 4):
        gl.glUniformMatrix4fv(location, 1, gl.GL_TRUE, np.asarray(value, np.float32))
    else:
        gl.glUniform3f(location, *(float(x) for x in np.asarray(value, np.float32)))
