// Out-of-line helpers of gl_test_util.h (the GL calls stay out of the header).
#include "gl_test_util.h"

#include <algorithm>

#include <epoxy/gl.h>

namespace patchcull::gl::test {

ScratchBuffer::ScratchBuffer(std::size_t bytes) {
    passes();
    glCreateBuffers(1, &name_);
    std::vector<std::uint8_t> zeros(std::max<std::size_t>(bytes, 16), 0);
    glNamedBufferData(name_, static_cast<GLsizeiptr>(zeros.size()), zeros.data(), GL_DYNAMIC_DRAW);
}

ScratchBuffer::~ScratchBuffer() { glDeleteBuffers(1, &name_); }

std::vector<float> ScratchBuffer::read_floats(std::size_t count) const {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> out(count);
    if (count) glGetNamedBufferSubData(name_, 0, static_cast<GLsizeiptr>(count * sizeof(float)), out.data());
    return out;
}

void cull_frustum(PatchRenderer& r, const FrustumPlanes& planes, std::vector<float>* plane_values) {
    static CullStatusPass status(passes());
    static FrustumPass frustum(passes());
    const PatchBuffers buffers = r.patch_buffers();
    status.begin(buffers);
    if (!plane_values) {
        frustum.run(buffers, planes);
        return;
    }
    ScratchBuffer values(6 * buffers.count * sizeof(float));
    frustum.run(buffers, planes, values.name());
    *plane_values = values.read_floats(6 * buffers.count);
}

}  // namespace patchcull::gl::test
