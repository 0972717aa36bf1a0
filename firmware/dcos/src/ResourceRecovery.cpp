#include <dcos/internal/ResourceRecovery.hpp>

extern "C" {
// Provided by the linker: the bounds of the dcos_resource_recovery section.
extern const dcos::internal::ResourceRecovery __start_dcos_resource_recovery[];
extern const dcos::internal::ResourceRecovery __stop_dcos_resource_recovery[];
}

namespace dcos::internal {

unsigned recoverResourcesOf(ObjectId deadTask)
{
    unsigned recovered = 0;
    for (const ResourceRecovery* entry = __start_dcos_resource_recovery; entry != __stop_dcos_resource_recovery;
         ++entry) {
        recovered += entry->recover(deadTask);
    }
    return recovered;
}

} // namespace dcos::internal
