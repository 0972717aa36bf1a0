// The segmented heap memory agent's interface object (seed 7.8): each
// primitive forwards to the kernel side, internal::HeapManager.
#include <dcos/HeapAgent.hpp>
#include <dcos/internal/HeapManager.hpp>

namespace dcos {

using internal::HeapManager;

Result<ObjectId> HeapAgent::Create(void* area, size_t areaBytes, const char* name, Visibility visibility) const
{
    return HeapManager::Create(area, areaBytes, name, visibility);
}

Status HeapAgent::Delete(ObjectId heap) const { return HeapManager::Delete(heap); }

// Allocate and Return, with the table's inline lookup, are in HeapManager.cpp.

Result<HeapStatistics> HeapAgent::GetStatistics(ObjectId heap) const { return HeapManager::GetStatistics(heap); }

Result<ObjectId> HeapAgent::NameToObject(const char* name) const
{
    return HeapManager::NameToObject(name, Visibility::Local);
}

Status HeapAgent::AddObjects(size_t count) const { return HeapManager::AddObjects(count); }

Status HeapAgent::XferOwnership(ObjectId heap, ObjectId newOwner) const
{
    return HeapManager::XferOwnership(heap, newOwner);
}

Status HeapAgent::XferOwnership(ObjectId heap, void* segment, ObjectId newOwner) const
{
    return HeapManager::XferOwnership(heap, segment, newOwner);
}

} // namespace dcos
