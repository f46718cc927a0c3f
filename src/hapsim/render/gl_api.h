// Private to the render layer: the OpenGL core API without a loader library. glvnd's libOpenGL
// exports every core function, and it dispatches to whichever context is current (EGL here, GLX
// under a GLFW window), so plain prototypes are enough. Not included by any public header.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
