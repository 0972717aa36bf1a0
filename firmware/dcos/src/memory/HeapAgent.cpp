// The segmented heap memory agent's interface object (seed 7.8): each
// primitive forwards to the kernel side, internal::HeapManager.
#include <dcos/HeapAgent.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/HeapManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

namespace dcos {

using internal::HeapManager;

DCOS_CONFIGURATION_SERVICE Result<ObjectId> HeapAgent::Create(void* area, size_t areaBytes, const char* name, Visibility visibility)
{
    return HeapManager::Create(area, areaBytes, name, visibility);
}

DCOS_CONFIGURATION_SERVICE Status HeapAgent::Delete(ObjectId heap) { return HeapManager::Delete(heap); }

// Allocate and Return, with the table's inline lookup, are in HeapManager.cpp.

Result<HeapStatistics> HeapAgent::GetStatistics(ObjectId heap) { return HeapManager::GetStatistics(heap); }

DCOS_CONFIGURATION_SERVICE Result<ObjectId> HeapAgent::NameToObject(const char* name)
{
    return internal::orRemoteName(HeapManager::NameToObject(name, Visibility::Local), ObjectType::Heap, name);
}

DCOS_CONFIGURATION_SERVICE Status HeapAgent::AddObjects(size_t count) { return HeapManager::AddObjects(count); }

DCOS_CONFIGURATION_SERVICE Status HeapAgent::XferOwnership(ObjectId heap, ObjectId newOwner)
{
    return HeapManager::XferOwnership(heap, newOwner);
}

DCOS_CONFIGURATION_SERVICE Status HeapAgent::XferOwnership(ObjectId heap, void* segment, ObjectId newOwner)
{
    return HeapManager::XferOwnership(heap, segment, newOwner);
}

} // namespace dcos
