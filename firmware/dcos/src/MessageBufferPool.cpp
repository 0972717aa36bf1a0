#include <dcos/internal/MessageBufferPool.hpp>
#include <dcos/internal/ConfigurationService.hpp>

namespace dcos::internal {

DCOS_CONFIGURATION_SERVICE Status MessageBufferPool::AddMsgBufs(size_t count)
{
    if (count == 0) {
        return Status::InvalidArgument;
    }
    if (count > capacity_ - active_) {
        return Status::NoMemory;
    }
    for (size_t i = 0; i < count; ++i) {
        give(reserve_[active_ + i]);
    }
    active_ += count;
    return Status::Ok;
}

// take() and give() are inline in the header.

void MessageBufferPool::giveChain(MessageBuffer& first, MessageBuffer& last, size_t count)
{
    last.next = freeHead_;
    freeHead_ = &first;
    free_ += count;
}

} // namespace dcos::internal
