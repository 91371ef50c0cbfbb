"""The shaders' GLSL functions evaluated by OpenGL itself, one fragment per query: a 1 x n
draw whose fragment k reads its query's inputs from rows of a float32 texture and writes
one vec4, read back in float32. What the searches of the shaders' laws stand on
(docs/accuracy.md); TRAJ2EVENTS_TEST_BACKEND=egl runs them on a GPU's driver."""

import os

import numpy as np

from traj2events.renderer.context import gl_context
from traj2events.renderer.glsl import compile_program, expand_includes, set_uniform, with_defines

QUERY_VERT = """#version 330 core
void main() { vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2); gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0); }
"""
QUERY_FRAG = """#version 330 core
uniform sampler2D queries;
vec4 query(int row) { return texelFetch(queries, ivec2(int(gl_FragCoord.x), row), 0); }
{declarations}
out vec4 result;
void main() { result = {expression}; }
"""
QUERY_UNIT = 7  # the queries' texture unit, above those the shaders' own textures take


class FragmentQueries:
    """`expression` (GLSL, a vec4 of `query(row)`, the row's vec4 at this fragment's
    query) after `declarations` (GLSL: includes, uniforms, functions), evaluated at n
    queries per call; `defines` set as the renderer sets them. A context manager: its
    OpenGL context lives until the block ends."""

    def __init__(self, declarations: str, expression: str, n: int, defines: tuple[str, ...] = ()):
        self.n = n
        self.context = gl_context(os.environ.get("TRAJ2EVENTS_TEST_BACKEND", "osmesa"), n, 1)
        from OpenGL import GL as gl

        self.gl = gl
        fragment = QUERY_FRAG.replace("{declarations}", declarations).replace("{expression}", expression)
        fragment = with_defines(expand_includes(fragment), defines)
        self.program = compile_program(
            gl, ((gl.GL_VERTEX_SHADER, "queries.vert", QUERY_VERT), (gl.GL_FRAGMENT_SHADER, "queries.frag", fragment))
        )
        gl.glUseProgram(self.program)
        self.uniforms(queries=QUERY_UNIT)
        gl.glActiveTexture(gl.GL_TEXTURE0 + QUERY_UNIT)
        gl.glBindTexture(gl.GL_TEXTURE_2D, gl.glGenTextures(1))
        gl.glTexParameteri(gl.GL_TEXTURE_2D, gl.GL_TEXTURE_MIN_FILTER, gl.GL_NEAREST)  # no levels: complete
        gl.glBindRenderbuffer(gl.GL_RENDERBUFFER, gl.glGenRenderbuffers(1))
        gl.glRenderbufferStorage(gl.GL_RENDERBUFFER, gl.GL_RGBA32F, n, 1)
        gl.glBindFramebuffer(gl.GL_FRAMEBUFFER, gl.glGenFramebuffers(1))
        gl.glFramebufferRenderbuffer(gl.GL_FRAMEBUFFER, gl.GL_COLOR_ATTACHMENT0, gl.GL_RENDERBUFFER,
                                     gl.glGetIntegerv(gl.GL_RENDERBUFFER_BINDING))  # fmt: skip
        gl.glViewport(0, 0, n, 1)
        gl.glBindVertexArray(gl.glGenVertexArrays(1))

    def uniforms(self, **values) -> None:
        """Sets the program's uniforms by name (`set_uniform`'s types); those the compiler
        dropped as unused are skipped."""
        for name, value in values.items():
            set_uniform(self.gl, self.gl.glGetUniformLocation(self.program, name), value)

    def __call__(self, inputs: np.ndarray) -> np.ndarray:
        """The expression at each query of `inputs` ((rows, n, 4): row r of query k is
        query(r) at fragment k), (n, 4) float32."""
        gl, inputs = self.gl, np.ascontiguousarray(inputs, np.float32)
        assert inputs.shape[1:] == (self.n, 4), inputs.shape
        gl.glActiveTexture(gl.GL_TEXTURE0 + QUERY_UNIT)
        gl.glTexImage2D(gl.GL_TEXTURE_2D, 0, gl.GL_RGBA32F, self.n, len(inputs), 0, gl.GL_RGBA, gl.GL_FLOAT, inputs)
        gl.glDrawArrays(gl.GL_TRIANGLES, 0, 3)
        pixels = gl.glReadPixels(0, 0, self.n, 1, gl.GL_RGBA, gl.GL_FLOAT)
        return np.frombuffer(pixels, np.float32).reshape(self.n, 4).copy()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.context.delete_context()
