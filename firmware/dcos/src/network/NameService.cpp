// This node's objects by type and name, for other nodes' name queries (NameService.hpp).
#include <dcos/internal/BufferPoolManager.hpp>
#include <dcos/internal/DeviceManager.hpp>
#include <dcos/internal/DsmManager.hpp>
#include <dcos/internal/HeapManager.hpp>
#include <dcos/internal/NameService.hpp>
#include <dcos/internal/PortManager.hpp>
#include <dcos/internal/SemaphoreManager.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>

namespace dcos::internal {

Result<ObjectId> localNameToObject(ObjectType type, const char* name, Visibility askingScope)
{
    switch (type) {
    case ObjectType::Task: return TaskManager::nameToObject(name, askingScope);
    case ObjectType::Timer: return TimerManager::timerNameToObject(name, askingScope);
    case ObjectType::Device: return deviceManager().NameToObject(name, askingScope);
    case ObjectType::BufferPool: return BufferPoolManager::NameToObject(name, askingScope);
    case ObjectType::Heap: return HeapManager::NameToObject(name, askingScope);
    case ObjectType::MessagePort: return PortManager::nameToObject(name, askingScope);
    case ObjectType::DsmPublisher: return DsmManager::publisherNameToObject(name, askingScope);
    case ObjectType::Semaphore: return semaphoreNameToObject(name, askingScope);
    default: return Status::NotFound;
    }
}

} // namespace dcos::internal
