// Occlusion-query proxy fragment shader (gl_object_queries.h): nothing to write (colour and depth
// writes are off); the depth test alone decides which samples a query counts.
#version 450 core

void main() {}
